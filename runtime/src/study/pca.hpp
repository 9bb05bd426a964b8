// The parameter clouds in one PCA basis (paper Fig. pca_clouds) and the representative
// selection by centrality (Sec. IV-C): every run's OLS, SDP and CLIE vectors are standardized
// by the pooled mean and standard deviation per parameter (so kg m, kg m^2 and N m s/rad
// compare), the principal directions come from the pooled cloud, and each stage's cloud is
// scored on them. The representative is the CLIE vector closest to its cloud's centre.
#pragma once

#include <vector>

#include "symoro/study/result.hpp"

namespace symoro::study {

// Runs without a CLIE vector (a divergent start) are scored on OLS/SDP only (CLIE row NaN).
PcaClouds pca_clouds(const std::vector<RunRecord>& runs, int components = 3);

// Centrality of each run's CLIE vector: the distance to the CLIE cloud's coordinate-wise median
// in the first k principal scores, each divided by the cloud's robust spread (1.4826 MAD) along
// it, k the smallest count explaining `variance_fraction` of the pooled variance (at most the
// components available). Only runs whose CLIE succeeded are candidates.
Selection select_central(const std::vector<RunRecord>& runs, const PcaClouds& pca, double variance_fraction = 0.9);

// Trace of the covariance of the standardized vectors: one number for a cloud's dispersion.
double cloud_dispersion(const std::vector<Eigen::VectorXd>& cloud, const PcaClouds& pca);

}  // namespace symoro::study
