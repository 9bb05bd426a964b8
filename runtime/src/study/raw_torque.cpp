#include "symoro/study/raw_torque.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "symoro/preprocess/preprocess.hpp"

namespace symoro::study {

namespace {
preprocess::Options raw_options(const RawTorqueOptions& options) {
  preprocess::Options po;
  po.derivative_cutoff = options.cutoff;
  po.filter_torque = false;
  // qd and qdd from q, zero phase: a controller's logged velocity is its own causal estimate,
  // late by its filter's delay, and would favour a model fitted on the same late signal.
  po.use_logged_velocity = false;
  return po;
}
}  // namespace

preprocess::Samples raw_torque_samples(const io::Log& log, const RawTorqueOptions& options) {
  const preprocess::Options po = raw_options(options);
  return preprocess::preprocess(log, preprocess::base_period(log, po), po);
}

Eigen::VectorXd raw_torque_floor(const io::Log& log, const preprocess::Samples& raw, const RawTorqueOptions& options) {
  preprocess::Options po = raw_options(options);
  po.filter_torque = true;  // the same samples (the settling trim follows the motion), torque low-passed
  const preprocess::Samples low = preprocess::preprocess(log, preprocess::base_period(log, po), po);
  if (low.time != raw.time) throw std::logic_error("raw_torque_floor: the filtered samples are not the raw ones");
  const Eigen::MatrixXd above = raw.tau - low.tau;
  return (above.colwise().squaredNorm() / static_cast<double>(above.rows())).cwiseSqrt().transpose();
}

std::string raw_torque_filter_text(const RawTorqueOptions& options) {
  return fmt::format(
      "raw torque (stale rows out, on the log's own-period grid, unfiltered); the model on the logged position "
      "through a zero-phase order-4 Butterworth low-pass at {:g} Hz, qd and qdd its central differences",
      options.cutoff);
}

RawTorqueScore raw_torque_error(const io::Log& log, const OpenLoopTorque& model, const Eigen::VectorXd& phi,
                                const RawTorqueOptions& options) {
  const preprocess::Samples raw = raw_torque_samples(log, options);
  RawTorqueScore r = raw_torque_error(raw, model, phi, options);
  r.floor_joint = raw_torque_floor(log, raw, options);
  return r;
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
