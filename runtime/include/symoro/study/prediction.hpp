// A model's inverse-dynamics torque on a log's measured motion, beside the measured torque
// (dynid predict, symoro.predict): q, qd and qdd from the identification's own preprocessing
// (time axis, zero-phase filter, derivatives, the sampling interval), so the numbers compare
// with a study's; and the error against the raw torque at the log's own rate (raw_torque.hpp).
#pragma once

#include <Eigen/Core>

#include "symoro/identify/identification_model.hpp"
#include "symoro/study/raw_torque.hpp"
#include "symoro/io/log.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::study {

struct Prediction {
  preprocess::Samples samples;  // the preprocessed motion and measured torque
  Eigen::MatrixXd tau_model;    // samples x joints: ID(q, qd, qdd; phi)
  Eigen::VectorXd rmse, rms;    // per joint: of tau - tau_model, and of tau (N m)
  RawTorqueScore raw;           // against the raw torque
};

// The defaults of dynid predict and symoro.predict (which take theirs from here).
struct PredictionOptions {
  // s: the sampling interval the log is preprocessed at (10 ms: the finest of the study's
  // intervals, preprocess::paper_intervals()).
  double interval = 0.010;
  // s the logged torque lags the links' (preprocess::Options::torque_delay); the study's other
  // preprocessing options are its defaults.
  double torque_delay = 0;
};

// Throws DataError as preprocess::preprocess does.
Prediction predict(const io::Log& log, const identify::IdentificationModel& model, const Eigen::VectorXd& phi,
                   const PredictionOptions& options = {});

}  // namespace symoro::study
