// Synchronized point-to-point moves and holds.
#include "symoro/trajectory/move.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace symoro::trajectory {

Segment plan_move(double start, const Eigen::VectorXd& from, const Eigen::VectorXd& to, const Eigen::VectorXd& velocity,
                  const Eigen::VectorXd& acceleration) {
  const Eigen::Index n = from.size();
  if (to.size() != n || velocity.size() != n || acceleration.size() != n)
    throw std::invalid_argument("plan_move: waypoints and limits differ in size");
  Segment segment;
  segment.start = start;
  segment.from = from;
  segment.to = to;
  // On the normalized profile joint j moves |to_j - from_j| per unit of s, so the limits of s
  // are the tightest of v_j / D_j and a_j / D_j over the joints that move.
  double s_velocity = std::numeric_limits<double>::infinity();
  double s_acceleration = std::numeric_limits<double>::infinity();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double distance = std::abs(to[j] - from[j]);
    if (distance == 0) continue;
    if (!(velocity[j] > 0) || !(acceleration[j] > 0))
      throw std::invalid_argument("plan_move: velocity and acceleration limits must be positive");
    s_velocity = std::min(s_velocity, velocity[j] / distance);
    s_acceleration = std::min(s_acceleration, acceleration[j] / distance);
  }
  if (std::isinf(s_velocity)) return segment;  // nothing moves: an empty segment
  segment.profile = Profile::plan(s_velocity, s_acceleration);
  return segment;
}

Segment plan_hold(double start, const Eigen::VectorXd& at, double duration) {
  Segment segment;
  segment.start = start;
  segment.from = at;
  segment.to = at;
  segment.profile = Profile::hold(duration);
  return segment;
}

}  // namespace symoro::trajectory
