// The data a model-gap diagnosis works on: the samples of several trajectories stacked one
// after the other, the identified model's regressor and fixed torque at every sample, the
// columns of the robot's full OpenSYMORO model that the identified model leaves out (products
// of inertia), and the candidate effects' own columns. Rows of the regressors are sample s,
// joint j -> s * joints + j, as in identify/regression.hpp. Built by stack_builder.hpp.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::diagnose {

struct DesignStack {
  int joints = 0;
  std::vector<std::string> joint_names;
  double interval = 0;  // s, the grid of every trajectory
  // What every column went through (stack_builder.hpp): the logs' period and the zero-phase
  // Butterworth low-pass; 0 when unknown. Columns computed later from the fit (backlash) are
  // re-made at this rate and through this filter, as the data were.
  double base_interval = 0, cutoff = 0;
  int filter_order = 0;
  Eigen::MatrixXd q, qd, qdd, tau;              // samples x joints
  Eigen::VectorXd time;                         // s, within its trajectory
  std::vector<int> segment;                     // per sample: a contiguous piece (trajectory x log piece)
  std::vector<std::string> segment_trajectory;  // per segment
  Eigen::MatrixXd W;                            // identified model, (samples * joints) x np
  Eigen::VectorXd tau0;                         // its fixed parameters' torque, same rows
  std::vector<std::string> parameters;          // identified parameter names
  Eigen::VectorXd rotor_inertia_index;          // per joint: index of IA<j> in `parameters`, -1 if none
  Eigen::VectorXd viscous_index;                // per joint: index of FV<j>, -1 if none
  // Full-model columns that are not identified parameters (name, family, joint).
  Eigen::MatrixXd full_extra;
  std::vector<std::string> full_extra_names, full_extra_families;
  std::vector<int> full_extra_joints;
  // Candidate effects' columns computed before the low-pass (effects.hpp: key -> samples x
  // parameters, the values on the candidate's joint).
  std::map<std::string, Eigen::MatrixXd> effect_terms;
  // A payload on the last link with a mass parameter (`payload_link`): the base parameters
  // that a unit of that link's standard M, MX, MY, MZ adds (np x 4, the identified model's
  // base_from_standard), so that the payload's torque is W payload_map (m, m px, m py, m pz).
  // Empty when the model has no such link.
  Eigen::MatrixXd payload_map;
  int payload_link = 0;
  // Held parameters (`dynid diagnose --params`: the gap of an earlier identification): when
  // set (size np), W held_phi is part of tau0 and the selection fits the effects alone, so
  // what changed since (a payload) is not absorbed by a refit.
  Eigen::VectorXd held_phi;
  bool held() const { return held_phi.size() > 0; }
  // Holds the identified parameters at phi (tau0 += W phi).
  void hold(const Eigen::VectorXd& phi);

  int samples() const { return static_cast<int>(q.rows()); }
  Eigen::Index rows() const { return static_cast<Eigen::Index>(samples()) * joints; }
  // y = tau - tau0, stacked.
  Eigen::VectorXd target() const;
  // The stacked rows of a samples x joints matrix.
  Eigen::VectorXd stacked(const Eigen::MatrixXd& per_sample) const;
  // d/dt of a samples x joints signal along each segment (central differences, one-sided at
  // the ends of a segment).
  Eigen::MatrixXd rate(const Eigen::MatrixXd& per_sample) const;
  // A pointwise function of a smooth grid signal (samples x channels) as the data would show
  // it: interpolated linearly to the logs' period, mapped by f there, low-passed by the
  // stack's filter, then sampled back on the grid with its first and second time derivatives.
  // A sharp f (a sign) would otherwise be differentiated on the grid, where the low-pass that
  // smooths it in the data is missing. Without the filter's data: f on the grid, rate().
  struct Filtered {
    Eigen::MatrixXd value, rate, accel;
  };
  Filtered filtered(const Eigen::MatrixXd& per_sample, const std::function<double(double)>& f) const;
};

}  // namespace symoro::diagnose
