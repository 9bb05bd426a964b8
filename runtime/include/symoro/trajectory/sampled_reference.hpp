// A reference sampled at every control cycle: what a controller steps through, cycle by cycle.
// It comes from a designed trajectory (evaluated at k T) or from a log's reference columns
// (the controller's own q_ref, qd_ref, qdd_ref), so that a simulation of the experiment can
// replay the motion that was logged, for any robot, without a trajectory design.
#pragma once

#include <string>

#include <Eigen/Core>

#include "symoro/io/log.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::trajectory {

// Cycle k = 0..K at t = k period: joints x (K + 1) matrices.
struct SampledReference {
  std::string name;
  double period = 0;
  Eigen::MatrixXd q, qd, qdd;
  int cycles() const { return static_cast<int>(q.cols()); }
  int joints() const { return static_cast<int>(q.rows()); }
  double duration() const { return cycles() > 0 ? (cycles() - 1) * period : 0.0; }
};

// A designed trajectory evaluated at each cycle (K = round(duration / period)).
SampledReference sample(const Trajectory& trajectory, double period);

// A log's reference columns, its time counted from its first stamp: each cycle takes the row
// stamped nearest its instant (a controller steps through references by cycle; stamp jitter
// moves the stamp, not the reference); a cycle without a row (a dropped read) is interpolated
// linearly between its neighbours. Throws DataError (naming the trajectory) when the log has no
// reference columns, fewer than 2 rows, or rows not one period apart (median within 10 %).
SampledReference sampled_reference(const io::Log& log, double period);

}  // namespace symoro::trajectory
