// Evaluation of a trajectory: find the segment that holds t, interpolate along its profile.
#include "symoro/trajectory/trajectory.hpp"

#include <algorithm>
#include <stdexcept>

#include "symoro/trajectory/fourier.hpp"

namespace symoro::trajectory {

void Trajectory::evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd,
                          Eigen::Ref<Eigen::VectorXd> qdd) const {
  if (segments.empty()) throw std::logic_error("Trajectory::evaluate: trajectory " + name + " is empty");
  if (q.size() != joints() || qd.size() != joints() || qdd.size() != joints())
    throw std::invalid_argument("Trajectory::evaluate: output size differs from the joint count");
  // The last segment starting at or before t (the first one for t < 0).
  auto after = std::upper_bound(segments.begin(), segments.end(), t,
                                [](double time, const Segment& s) { return time < s.start; });
  const Segment& segment = after == segments.begin() ? segments.front() : *std::prev(after);
  if (segment.periodic) {
    Eigen::VectorXd pq, pqd, pqdd;
    segment.periodic->evaluate(std::clamp(t - segment.start, 0.0, segment.profile.duration), pq, pqd, pqdd);
    q = pq;
    qd = pqd;
    qdd = pqdd;
    return;
  }
  double s = 0, sd = 0, sdd = 0;
  segment.profile.evaluate(t - segment.start, s, sd, sdd);
  if (!segment.profile.moves()) {
    q = segment.from;
    qd.setZero();
    qdd.setZero();
    return;
  }
  // From the nearer end, so that both waypoints are met exactly (expressions: no allocation).
  const auto displacement = segment.to - segment.from;
  if (s <= 0.5)
    q = segment.from + s * displacement;
  else
    q = segment.to - (1.0 - s) * displacement;
  qd = sd * displacement;
  qdd = sdd * displacement;
}

}  // namespace symoro::trajectory
