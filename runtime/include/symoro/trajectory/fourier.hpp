// A periodic excitation trajectory: a finite Fourier series per joint (Swevers et al., 1997), the
// parametrization optimized excitation designs use (issue 29). With base pulsation w and L
// harmonics, joint j moves as
//   q_j(t)   = q0_j + sum_l  a_jl / (w l) sin(w l t) - b_jl / (w l) cos(w l t)
//   qd_j(t)  =        sum_l  a_jl cos(w l t) + b_jl sin(w l t)
//   qdd_j(t) =        sum_l  w l (b_jl cos(w l t) - a_jl sin(w l t)),
// periodic with period 2 pi / w. It is at rest at t = 0, and so at the end of every period,
// when sum_l a_jl = 0 (qd) and sum_l l b_jl = 0 (qdd).
//
// Bounds over the whole motion, not only at samples: with r_jl = |(a_jl, b_jl)|,
//   |q_j - q0_j| <= sum_l r_jl / (w l),  |qd_j| <= sum_l r_jl,  |qdd_j| <= sum_l w l r_jl
// (each harmonic is a rotating vector of that length; equality for a single harmonic).
#pragma once

#include <string>

#include <Eigen/Core>

#include "symoro/trajectory/sampled_reference.hpp"

namespace symoro::trajectory {

struct FourierTrajectory {
  std::string name;
  double w = 0;          // rad/s
  Eigen::VectorXd q0;    // per joint: the series' offset
  Eigen::MatrixXd a, b;  // joints x harmonics

  int joints() const { return static_cast<int>(a.rows()); }
  int harmonics() const { return static_cast<int>(a.cols()); }
  double period() const;

  // q, qd, qdd at time t (resized to joints()).
  void evaluate(double t, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const;

  // The bounds above, per joint.
  Eigen::VectorXd position_bound() const;  // of |q - q0|
  Eigen::VectorXd velocity_bound() const;
  Eigen::VectorXd acceleration_bound() const;

  // The nearest coefficients (least squares, per joint) at rest at t = 0, and q0 so that
  // q(0) = start. Throws std::invalid_argument on sizes that do not match.
  void come_to_rest_at(const Eigen::VectorXd& start);

  // `periods` periods sampled every `period` s, both ends included (a reference the twin, the
  // controller and identification read).
  SampledReference sample(double period, int periods = 1) const;
};

}  // namespace symoro::trajectory
