// A designed trajectory sampled as a reference file (io::Log with source "reference").
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "symoro/trajectory/design.hpp"

namespace symoro::trajectory {

io::Log reference_log(const Trajectory& t, double period, const std::string& robot,
                      const std::vector<std::string>& joint_names) {
  if (!(period > 0) || !std::isfinite(period))
    throw std::invalid_argument("reference_log: the period must be positive");
  if (static_cast<int>(joint_names.size()) != t.joints())
    throw std::invalid_argument("reference_log: " + std::to_string(joint_names.size()) +
                                " joint names for trajectory " + t.name + " with " + std::to_string(t.joints()) +
                                " joints");
  const double duration = t.duration();
  if (!(duration > 0)) throw std::invalid_argument("reference_log: trajectory " + t.name + " is empty");
  // k * period for k < steps, and the end itself last (the final interval absorbs the rest).
  const long steps = std::max(1L, std::lround(duration / period));
  const Eigen::Index samples = steps + 1;
  const int n = t.joints();

  io::Log log;
  log.meta.robot = robot;
  log.meta.trajectory = t.name;
  log.meta.source = "reference";
  log.meta.sample_time = period;
  log.meta.joints = joint_names;
  log.meta.notes = t.description;
  log.time.resize(samples);
  log.q.resize(samples, 0);
  log.qd.resize(samples, 0);
  log.tau.resize(samples, 0);
  log.q_ref.resize(samples, n);
  log.qd_ref.resize(samples, n);
  log.qdd_ref.resize(samples, n);
  Eigen::VectorXd q(n), qd(n), qdd(n);
  for (Eigen::Index k = 0; k < samples; ++k) {
    const double time = k == steps ? duration : static_cast<double>(k) * period;
    t.evaluate(time, q, qd, qdd);
    log.time[k] = time;
    log.q_ref.row(k) = q.transpose();
    log.qd_ref.row(k) = qd.transpose();
    log.qdd_ref.row(k) = qdd.transpose();
  }
  return log;
}

}  // namespace symoro::trajectory
