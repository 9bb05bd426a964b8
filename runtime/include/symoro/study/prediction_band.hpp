// How far to trust a predicted torque: a band per sample and joint from the parameters'
// covariance and the residual's own level, and how often measured torque falls inside it.
//
// The error of a prediction w' phi_hat of a measured torque is the residual the model leaves
// (noise and what the model lacks, of its own level s_j per joint) plus w' (phi - phi_hat), the
// parameters' error. The band's half-width at a level (0.95) is z sqrt(w' C w + s_j^2): C the
// covariance of phi (Newey-West over the identification samples, the residual's autocorrelation
// counted: identify/hac_covariance.hpp), s_j the residual's RMS on those samples, z the
// two-sided normal quantile. Whether the band is honest is measured, not assumed: `coverage`,
// the share of samples whose measured torque falls inside, on data the parameters were not fitted
// to (the study's held-out runs, dynid predict's logs).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/identification_model.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/study/prediction_uncertainty.hpp"

namespace symoro::study {

// Of `phi` fitted on `samples` (the identification's own): the least-squares covariance by
// Newey-West around phi's residual, and the residual's RMS per joint.
PredictionUncertainty prediction_uncertainty(const identify::IdentificationModel& model,
                                             const std::vector<preprocess::Samples>& samples,
                                             const Eigen::VectorXd& phi, const std::string& source);

// The band's half-width, samples x joints, at `level` (0 < level < 1).
Eigen::MatrixXd prediction_band(const identify::IdentificationModel& model, const preprocess::Samples& samples,
                                const PredictionUncertainty& u, double level = 0.95);

// The share of samples (per joint, and over all) with |tau - tau_model| <= band.
struct BandCoverage {
  Eigen::VectorXd joint;
  double all = 0;
  int samples = 0;
};
BandCoverage band_coverage(const Eigen::MatrixXd& tau, const Eigen::MatrixXd& tau_model, const Eigen::MatrixXd& band);

// report/uncertainty.yaml beside a study's report/parameters.yaml: written by the study, read by
// dynid predict and symoro.predict. The reader checks the parameter names (DataError at
// file:line).
std::string uncertainty_yaml(const PredictionUncertainty& u, const std::string& robot);
PredictionUncertainty read_uncertainty_yaml(const std::string& file, const std::vector<std::string>& names);

}  // namespace symoro::study
