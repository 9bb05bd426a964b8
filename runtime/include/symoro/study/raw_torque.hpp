// A model scored against the raw measured torque, at the log's own rate: the numbers a plain
// least-squares user would compare with, next to the study's filtered ones. The torque is the
// log's (stale rows out, brought onto the corrected 1 kHz grid, not filtered); the model is
// evaluated on the logged motion with the evaluation's own acceleration filter, stated in every
// report: q through a zero-phase Butterworth low-pass (order 4, `cutoff`), qd and qdd its
// central differences. Not the logged velocity: a controller's is its own causal estimate, late
// by its filter's delay, and would favour a model fitted on the same late signal (the truth
// scored 1.96 N m on an RX-90 log whose velocity came through an 80 Hz first-order filter, a
// fit on that velocity 1.36).
#pragma once

#include <string>

#include <Eigen/Core>

#include "symoro/study/validation.hpp"
#include "symoro/io/log.hpp"

namespace symoro::study {

struct RawTorqueOptions {
  double cutoff = 20;  // Hz: the motion's low-pass for the model's qdd
};

struct RawTorqueScore {
  TorqueError error;
  int samples = 0;
  std::string filter;  // what the evaluation did, one sentence for reports
  // Per joint: the RMS of the raw torque's own content above `cutoff` (the raw torque minus its
  // zero-phase low-pass at the cutoff, on the same samples; raw_torque_floor). A model of the
  // motion through that low-pass follows next to none of it: the error's floor on this log, sensor
  // noise and dynamics beyond the band alike. Empty from the samples-only overload.
  Eigen::VectorXd floor_joint;
};

// Throws DataError (naming the log) as preprocess::preprocess does.
RawTorqueScore raw_torque_error(const io::Log& log, const OpenLoopTorque& model, const Eigen::VectorXd& phi,
                                const RawTorqueOptions& options = {});
// The same on samples raw_torque_samples made (several vectors on one log: preprocessed once).
RawTorqueScore raw_torque_error(const preprocess::Samples& samples, const OpenLoopTorque& model,
                                const Eigen::VectorXd& phi, const RawTorqueOptions& options = {});

// RawTorqueScore::floor_joint of a log: sqrt(mean((tau_raw - tau_lowpass)^2)) per joint over
// `raw`, the samples raw_torque_samples made of it (the log preprocessed once more, torque
// low-passed).
Eigen::VectorXd raw_torque_floor(const io::Log& log, const preprocess::Samples& raw,
                                 const RawTorqueOptions& options = {});

// The motion and raw torque raw_torque_error scores on (Samples at the log's base period).
preprocess::Samples raw_torque_samples(const io::Log& log, const RawTorqueOptions& options = {});

std::string raw_torque_filter_text(const RawTorqueOptions& options);

}  // namespace symoro::study
