// How informative a motion is about a model's base parameters (issue 29's first piece, what
// `dynid trajectories --quality` prints): the stacked regressor W of its samples judged by
//   - kappa: sigma_max / sigma_min of W, the paper's condition number (unit dependent);
//   - kappa_scaled: the same with W's columns scaled to unit norm, so that a parameter's unit
//     (kg against kg m^2) does not count as poor excitation;
//   - log_det_scaled: log det of the column-scaled W'W = 2 sum log sigma_i, the D-optimality
//     criterion of an excitation design (larger is better; per row, so that designs of
//     different lengths compare);
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

namespace symoro::identify {

struct ExcitationQuality {
  int rows = 0;
  double kappa = std::numeric_limits<double>::infinity();
  double kappa_scaled = std::numeric_limits<double>::infinity();
  double log_det_scaled = -std::numeric_limits<double>::infinity();  // of W_s'W_s / rows
  double sigma_min_scaled = 0;
  std::vector<std::pair<std::string, double>> weakest;  // name, component of the weakest direction
  std::vector<std::string> unexcited;                  // parameters whose column is zero
};

// From a stacked regressor (rows x parameters). `top`: how many components of the weakest
// direction to name. Throws std::invalid_argument when the names do not match W's columns.
ExcitationQuality excitation_quality(const Eigen::MatrixXd& W, const std::vector<ParameterInfo>& parameters, int top = 3);

// A reference motion as identification samples every `interval` s: its own q, qd, qdd (no
// preprocessing: they are exact), torque 0.
preprocess::Samples reference_samples(const trajectory::SampledReference& reference, double interval);

// The regression of a reference motion (reference_samples) judged as above.
ExcitationQuality excitation_quality(const IdentificationModel& model, const trajectory::SampledReference& reference,
                                     double interval, int top = 3);

}  // namespace symoro::identify
