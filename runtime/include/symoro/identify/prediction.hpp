// A model's inverse-dynamics torque on a log's measured motion, beside the measured torque
// (dynid predict, symoro.predict): q, qd and qdd from the identification's own preprocessing
// (time axis, zero-phase filter, derivatives, the sampling interval), so the numbers compare
// with a study's; and the error against the raw torque at the log's own rate (raw_torque.hpp).
#pragma once

#include <Eigen/Core>

#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/raw_torque.hpp"
#include "symoro/io/log.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::identify {

struct Prediction {
  preprocess::Samples samples;  // the preprocessed motion and measured torque
  Eigen::MatrixXd tau_model;    // samples x joints: ID(q, qd, qdd; phi)
  Eigen::VectorXd rmse, rms;    // per joint: of tau - tau_model, and of tau (N m)
  RawTorqueScore raw;           // against the raw torque
};

// interval and torque_delay in s (preprocess::Options::torque_delay; the study's other options).
// Throws DataError as preprocess::preprocess does.
Prediction predict(const io::Log& log, const IdentificationModel& model, const Eigen::VectorXd& phi, double interval,
                   double torque_delay = 0);

}  // namespace symoro::identify
