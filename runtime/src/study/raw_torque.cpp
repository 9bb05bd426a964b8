#include "symoro/study/raw_torque.hpp"

#include <fmt/format.h>

#include "symoro/preprocess/preprocess.hpp"

namespace symoro::study {

preprocess::Samples raw_torque_samples(const io::Log& log, const RawTorqueOptions& options) {
  preprocess::Options po;
  po.derivative_cutoff = options.cutoff;
  po.filter_torque = false;
  // qd and qdd from q, zero phase: a controller's logged velocity is its own causal estimate,
  // late by its filter's delay, and would favour a model fitted on the same late signal.
  po.use_logged_velocity = false;
  const double base = preprocess::base_period(log, po);
  return preprocess::preprocess(log, base, po);
}

std::string raw_torque_filter_text(const RawTorqueOptions& options) {
  return fmt::format(
      "raw torque (stale rows out, on the log's own-period grid, unfiltered); the model on the logged position "
      "through a zero-phase order-4 Butterworth low-pass at {:g} Hz, qd and qdd its central differences",
      options.cutoff);
}

RawTorqueScore raw_torque_error(const io::Log& log, const OpenLoopTorque& model, const Eigen::VectorXd& phi,
                                const RawTorqueOptions& options) {
  return raw_torque_error(raw_torque_samples(log, options), model, phi, options);
}

RawTorqueScore raw_torque_error(const preprocess::Samples& s, const OpenLoopTorque& model, const Eigen::VectorXd& phi,
                                const RawTorqueOptions& options) {
  RawTorqueScore r;
  r.error = torque_error(s.tau, model(s, phi));
  r.samples = static_cast<int>(s.tau.rows());
  r.filter = raw_torque_filter_text(options);
  return r;
}

}  // namespace symoro::study
