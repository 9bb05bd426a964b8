// The model feedforward checked before torque is enabled (ControlOptions::inertia): a parameters
// file says `accepted: true` whatever was edited in it, so the controller looks at what the model
// will command. One MX2 changed to 50 drove the virtual arm into a velocity stop; ZZR2 = -100 (a
// mass matrix that is not positive definite) ran to completion. Both are refused here.
#include <chrono>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "control_loop.hpp"

namespace symoro::hardware::detail {

void Loop::check_feedforward() {
  const auto t0 = Clock::now();
  const auto refuse = [](const std::string& why) {
    throw StopNow{StopReason::setup_failed, "the model feedforward is refused before torque on: " + why};
  };
  Eigen::MatrixXd M(n_, n_);
  const auto check_inertia = [&](const Eigen::VectorXd& q, const std::string& where) {
    if (!o_.inertia) return;
    o_.inertia(q, M);
    if (M.rows() != n_ || M.cols() != n_ || !M.allFinite())
      refuse(fmt::format("its mass matrix is not a finite {}x{} matrix {}", n_, n_, where));
    const Eigen::LLT<Eigen::MatrixXd> llt(M);
    if (llt.info() != Eigen::Success) {
      const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues()(0);
      refuse(fmt::format(
          "its mass matrix M(q) is not positive definite {} (smallest eigenvalue {:.4g}): these parameters are "
          "no physical arm",
          where, lambda));
    }
  };
  check_inertia(q0_, "at the measured start pose");
  // Every reference the loop will command, on its own grid (reference() is what loop() calls).
  Eigen::VectorXd ff(n_);
  for (std::int64_t k = 0; k <= k_end_; ++k) {
    const double t = reference(k * T_);
    const std::string where = t < 0 ? fmt::format("on the approach, {:.3f} s before the trajectory", -t)
                                    : fmt::format("at trajectory time {:.3f} s", t);
    o_.feedforward(qr_, qdr_, qddr_, ff);
    if (ff.size() != n_) refuse(fmt::format("it returns {} torques for {} joints", ff.size(), n_));
    for (int j = 0; j < n_; ++j) {
      if (!std::isfinite(ff(j)))
        refuse(fmt::format("joint {} {}: its torque is {} {}", j + 1, joints_[j].name, ff(j), where));
      const double bound = limit_(j) * kt_(j);
      if (std::abs(ff(j)) > bound)
        refuse(fmt::format("joint {} {}: its torque {:.4g} N m {} exceeds the joint's limit {:.4g} N m", j + 1,
                           joints_[j].name, ff(j), where, bound));
    }
    check_inertia(qr_, where);
  }
  feedforward_checked_ = true;
  if (o_.verbose)
    std::fprintf(stderr,
                 "control: model feedforward checked on %lld references (%s, torques within the limits) in %.2f s\n",
                 static_cast<long long>(k_end_ + 1),
                 o_.inertia ? "mass matrix positive definite" : "no mass matrix given", seconds(Clock::now() - t0));
}

}  // namespace symoro::hardware::detail
