// The closed-loop digital twin: the plant driven by the paper's FF+PD controller through the
// realization layer of a DYNAMIXEL arm, producing the log a real run would produce.
//
// One control cycle k (nominal period T, start t_k = k T + jitter):
//   t_k        the encoders are sampled (link-side, quantized, optional noise) and the
//              servos report their present current (quantized, optional noise); the log row
//              stamps t_k, and its torque is the one computed from that current with the
//              nominal torque constants, as on the real arm.
//   t_k + d    after the bus round trip d (reading 8 encoders and writing 8 commands) the new
//              current commands take effect and are held until the next ones (sample and
//              hold adds about T/2, so the total delay is about d + T/2). With the
//              actuation_delay effect the torque follows the command a further time later,
//              while the servo keeps reporting the commanded current.
// A dropped cycle (failed read) writes no row and the controller reuses its last measurement.
// Before t = 0 the controller holds the first reference for a pre-roll (not logged), as the
// real arm holds its start posture before a run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/control/ffpd.hpp"
#include "symoro/io/log.hpp"
#include "symoro/robot/model_handle.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/trajectory/trajectory.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/random.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::twin {

struct RunOptions {
  std::string robot;
  int trial = 1;
  std::uint64_t seed = 1;  // the run's own seed (see run_seed)
  double pre_roll = 0.5;   // s of holding the start posture before logging
};

struct RunStats {
  double simulated = 0;                        // s of logged motion
  double wall = 0;                             // s of computation
  int cycles = 0, dropped = 0, saturated = 0;  // saturated: cycles with a current at its limit
  Eigen::VectorXd max_error, rms_error;        // true q_ref - q, rad, per joint
  Eigen::VectorXd max_torque;                  // |applied motor torque|, N m, per joint
};

control::FfpdGains controller_gains(const TwinConfig& c);

class ClosedLoopTwin {
 public:
  // `model`: the robot's full model (any robot: a linked one, robot::compiled_model, or a loaded
  // library's); `config` its twin.yaml, read for model.nq() joints. DataError when they disagree.
  ClosedLoopTwin(robot::ModelHandle model, TwinConfig config);

  const TwinConfig& config() const { return c_; }
  const robot::ModelHandle& model() const { return model_; }
  int joints() const { return model_.nq(); }

  // What a log records about the twin that made it: the configuration file, its fingerprint
  // and the effects switched on (a dataset reruns a run whose notes differ).
  std::string notes() const;
  const Truth& truth() const { return truth_; }

  io::Log run(const trajectory::Trajectory& traj, const RunOptions& opt, RunStats* stats = nullptr) const;

  // The same with the reference of every cycle given (e.g. a log's own references: the motion
  // that was logged, replayed). Its period must be the controller's.
  io::Log run(const trajectory::SampledReference& ref, const RunOptions& opt, RunStats* stats = nullptr) const;

 private:
  robot::ModelHandle model_;
  TwinConfig c_;
  Truth truth_;
  std::vector<std::string> names_;
};

}  // namespace symoro::twin
