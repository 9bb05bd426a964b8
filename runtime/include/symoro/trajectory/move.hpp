// Segments from waypoints: a synchronized point-to-point move of all joints along one
// normalized profile, and a hold. The joint that needs longest (for its velocity or for its
// acceleration limit, scaled by its displacement) sets the timing; every other joint then stays
// below its own limits.
#pragma once

#include <Eigen/Core>

#include "symoro/trajectory/trajectory.hpp"

namespace symoro::trajectory {

// The move from `from` to `to` starting at `start`, with per-joint limits |qd_j| <= velocity_j
// and |qdd_j| <= acceleration_j (both > 0). A move with from == to has a 0 duration.
Segment plan_move(double start, const Eigen::VectorXd& from, const Eigen::VectorXd& to, const Eigen::VectorXd& velocity,
                  const Eigen::VectorXd& acceleration);

// Standing at `at` from `start` for `duration` seconds.
Segment plan_hold(double start, const Eigen::VectorXd& at, double duration);

}  // namespace symoro::trajectory
