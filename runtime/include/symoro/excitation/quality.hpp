// How informative a motion is about a model's base parameters (issue 29's first piece, what
// `dynid trajectories --quality` prints): the stacked regressor W of its samples judged by
//   - kappa: sigma_max / sigma_min of W, the paper's condition number (unit dependent);
//   - kappa_scaled: the same with W's columns scaled to unit norm, so that a parameter's unit
//     (kg against kg m^2) does not count as poor excitation;
//   - log_det_scaled: log det of W_s'W_s with W_s's columns of unit norm = 2 sum log sigma_i of
//     W_s: at most 0 (orthogonal columns), the more negative the more the parameters' columns
//     are alike. Unit columns make it independent of the units and of the motion's length and
//     amplitude: it measures how well the motion tells the parameters apart, not how strongly
//     it moves (the D-optimal design, excitation/design.hpp, maximizes log det with fixed
//     scales, which rewards both);
//   - the weakest direction: the right singular vector of the smallest scaled singular value,
//     its largest components named (what the motion excites least).
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/identification_model.hpp"
#include "symoro/model_info.hpp"
#include "symoro/trajectory/sampled_reference.hpp"

namespace symoro::excitation {

struct ExcitationQuality {
  int rows = 0;
  double kappa = std::numeric_limits<double>::infinity();
  double kappa_scaled = std::numeric_limits<double>::infinity();
  double log_det_scaled = -std::numeric_limits<double>::infinity();  // of W_s'W_s, unit columns
  double sigma_min_scaled = 0;
  std::vector<std::pair<std::string, double>> weakest;  // name, component of the weakest direction
  std::vector<std::string> unexcited;                   // parameters whose column is zero
};

// From a stacked regressor (rows x parameters). `top`: how many components of the weakest
// direction to name. Throws std::invalid_argument when the names do not match W's columns.
// raw_kappa false: kappa is left infinite (a caller that has it already saves an SVD of W).
ExcitationQuality excitation_quality(const Eigen::MatrixXd& W, const std::vector<ParameterInfo>& parameters,
                                     int top = 3, bool raw_kappa = true);

// W's triangular factor: the p x p upper triangular R of W = Q R (fewer rows when W has fewer than
// p), by Householder QR of blocks of rows in turn (R of [R; next block]: each block stays in
// cache, where one QR of a 10^5-row W runs its panels through memory). R holds all the measures
// need, W'W = R'R and the singular values of W, and factors stack: the R of [W1; W2] is the R of
// [R1; R2], so a design's whole is rated from its trajectories' factors.
Eigen::MatrixXd triangular_factor(const Eigen::MatrixXd& W);

// Whether singular values (descending) are those of a numerically singular matrix: the smallest
// at most p eps of the largest (the rank tolerance of a p x p factor), where its value is rounding.
bool numerically_singular(const Eigen::VectorXd& sigma);

// The measures of excitation_quality from W's triangular factor R and W's row count, the scaled
// ones from the singular values of R with unit columns (not squared through a Gram matrix); a
// numerically singular R (numerically_singular) has infinite kappas and log det -inf.
ExcitationQuality excitation_quality_of_factor(const Eigen::MatrixXd& R, Eigen::Index rows,
                                               const std::vector<ParameterInfo>& parameters, int top = 3);

// A reference motion as identification samples every `interval` s: its own q, qd, qdd (no
// preprocessing: they are exact), torque 0.
preprocess::Samples reference_samples(const trajectory::SampledReference& reference, double interval);

// The regression of a reference motion (reference_samples) judged as above.
ExcitationQuality excitation_quality(const identify::IdentificationModel& model,
                                     const trajectory::SampledReference& reference, double interval, int top = 3);

}  // namespace symoro::excitation
