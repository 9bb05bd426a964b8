// The pieces of an optimized excitation design (excitation/design.hpp) that tests check one by
// one: a Fourier series' coefficients as a vector x, the motion at the design's instants, the
// D-optimality criterion with its exact gradient, and the nominal torque and workspace
// constraints with their Jacobians.
//
// x holds, joint after joint, a_j1..a_jL then b_j1..b_jL (trajectory/fourier.hpp); q0 is not a
// variable: q(0) = start fixes it. At the instants t_k = (k + 1/2) T / N (k = 0..N-1 over one
// period T; off t = 0, where qd = 0 would put sign(qd) on its jump)
//   q(t_k) = start + Bq(k, :) x_j,  qd(t_k) = Bqd(k, :) x_j,  qdd(t_k) = Bqdd(k, :) x_j
// with Bq = [sin(w l t) / (w l), (1 - cos(w l t)) / (w l)], Bqd = [cos, sin] and
// Bqdd = [-w l sin, w l cos]: every joint's motion is linear in its 2 L coefficients.
//
// The criterion is f(x) = -log det(S W'W S / N), W the stacked regressor of the N instants and
// S a fixed diagonal column scaling. S shifts f by a constant only, so the optimum is the
// D-optimal design in any units; S keeps the matrix well scaled for the factorization. With
// C = S (S W'W S)^-1 S, df = -2 sum_k sum_i d(W_k(i, :) g_ki) with g_ki = (W_k C)(i, :)': the
// derivative of one row of W times a fixed vector, which IdentificationModel::state_derivatives
// gives exactly from the generated inverse-dynamics derivatives (no finite differences, no Jets).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/identification_model.hpp"
#include "symoro/trajectory/fourier.hpp"

namespace symoro::excitation {

// A workspace half-space on the origin p of a model frame (in frame 0, the base):
// normal . p <= offset, e.g. a table 5 cm below the base: frame f, normal (0, 0, -1), offset 0.05.
struct HalfSpace {
  std::string name;
  int frame = 1;  // 1-based model frame (its origin)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;
};

class FourierBasis {
 public:
  FourierBasis(int joints, int harmonics, double period, int samples, Eigen::VectorXd start);

  int joints() const { return n_; }
  int harmonics() const { return L_; }
  int samples() const { return N_; }
  int variables() const { return 2 * n_ * L_; }
  int block() const { return 2 * L_; }  // coefficients per joint
  double pulsation() const { return w_; }
  double period() const;
  double time(int k) const { return (k + 0.5) * period() / N_; }
  const Eigen::VectorXd& start() const { return start_; }
  // Basis rows (samples x 2L), as above.
  const Eigen::MatrixXd& bq() const { return bq_; }
  const Eigen::MatrixXd& bqd() const { return bqd_; }
  const Eigen::MatrixXd& bqdd() const { return bqdd_; }

  // The motion at the instants: samples x joints each.
  void states(const Eigen::VectorXd& x, Eigen::MatrixXd& q, Eigen::MatrixXd& qd, Eigen::MatrixXd& qdd) const;
  trajectory::FourierTrajectory trajectory(const Eigen::VectorXd& x, const std::string& name) const;
  // The coefficients of a series with this basis' harmonics and pulsation.
  Eigen::VectorXd coefficients(const trajectory::FourierTrajectory& t) const;

 private:
  int n_, L_, N_;
  double w_;
  Eigen::VectorXd start_;
  Eigen::MatrixXd bq_, bqd_, bqdd_;
};

class ExcitationCriterion {
 public:
  ExcitationCriterion(const identify::IdentificationModel& model, FourierBasis basis);

  const FourierBasis& basis() const { return basis_; }
  // The design's parameters theta when they are not the model's base parameters: phi = P theta
  // (np x r), e.g. a payload's 10 on the last link (payload/payload_identification.hpp). The
  // criterion is then log det of the column-scaled (W P)'(W P). Empty: P = 1. Resets the scales.
  void set_parameter_map(const Eigen::MatrixXd& P);
  int parameters() const;  // r
  // S: 1 / the column norms of W at x (1 for a column that is zero there).
  void scale_columns_at(const Eigen::VectorXd& x);
  const Eigen::VectorXd& scales() const { return scales_; }

  // f(x) as above and, when `gradient`, df/dx. Empty when S W'W S is not positive definite (a
  // parameter not excited).
  std::optional<double> value(const Eigen::VectorXd& x, Eigen::VectorXd* gradient = nullptr) const;

  // The nominal torque ID(q, qd, qdd; phi) at the instants: N x joints; with `jacobian`, row
  // k * joints + j holds d tau_j(t_k) / dx.
  Eigen::MatrixXd torque(const Eigen::VectorXd& x, const Eigen::VectorXd& phi,
                         Eigen::MatrixXd* jacobian = nullptr) const;

  // normal . p - offset per half-space h at the instants: N x spaces; with `jacobian`, row
  // k * spaces + h holds its derivative along x.
  Eigen::MatrixXd workspace(const Eigen::VectorXd& x, const std::vector<HalfSpace>& spaces,
                            Eigen::MatrixXd* jacobian = nullptr) const;

 private:
  const identify::IdentificationModel& model_;
  FourierBasis basis_;
  Eigen::VectorXd scales_;
  Eigen::MatrixXd map_;  // P, empty for the base parameters
  Eigen::MatrixXd regressor(const Eigen::MatrixXd& q, const Eigen::MatrixXd& qd, const Eigen::MatrixXd& qdd) const;
};

// normal . p - offset for each half-space at pose q, and with `dq` its derivative along q
// (spaces x joints): revolute joint i moves p by z_i x (p - o_i), prismatic by z_i, for the
// frames on p's chain. Throws std::invalid_argument for a frame the model does not have.
Eigen::VectorXd half_space_values(const std::vector<FrameInfo>& frames, const Eigen::VectorXd& q,
                                  const std::vector<HalfSpace>& spaces, Eigen::MatrixXd* dq = nullptr);

}  // namespace symoro::excitation
