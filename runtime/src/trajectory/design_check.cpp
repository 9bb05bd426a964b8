// The limits check of a built trajectory. It is exact, not sampled: along a segment every joint
// moves monotonically from one waypoint to the next (ds/dt >= 0), so its position extremes are
// the waypoints, and its speed peaks at |to - from| times the profile's peak velocity, reached
// at the end of the first ramp. A periodic segment (a Fourier series) is checked over one period
// every millisecond, the control period its references are stepped through.
#include <cmath>
#include <sstream>

#include "design_data.hpp"
#include "symoro/detail/numbers.hpp"
#include "symoro/error.hpp"
#include "symoro/trajectory/fourier.hpp"

namespace symoro::trajectory {

namespace {

using symoro::detail::kDeg;

std::string text(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}

}  // namespace

void check_limits(const Design& design, const TrajectorySpec& spec, const Trajectory& trajectory) {
  const std::string file = design.path.string();
  auto fail = [&](std::size_t j, double time, const std::string& what) {
    throw DataError(file, spec.line,
                    "trajectory " + spec.name + ": joint " + std::to_string(j + 1) + " (" + design.joint_names[j] +
                        ") " + what + " at t = " + text(time) + " s");
  };
  auto check_position = [&](const Eigen::VectorXd& q, double time) {
    for (std::size_t j = 0; j < design.joints.size(); ++j) {
      const JointInfo& joint = design.joints[j];
      const double low = joint.lower + design.position_margin, high = joint.upper - design.position_margin;
      if (q[j] < low || q[j] > high)
        fail(j, time,
             "reaches " + text(q[j] / kDeg) + " deg, outside [" + text(low / kDeg) + ", " + text(high / kDeg) +
                 "] deg (its limits less the " + text(design.position_margin / kDeg) + " deg margin)");
    }
  };
  if (trajectory.segments.empty()) throw DataError(file, spec.line, "trajectory " + spec.name + " is empty");
  check_position(trajectory.segments.front().from, 0.0);
  for (const Segment& s : trajectory.segments) {
    check_position(s.to, s.end());
    if (s.periodic) {
      Eigen::VectorXd q, qd, qdd;
      const double period = s.periodic->period();
      for (int k = 0; k * 1e-3 <= period; ++k) {
        s.periodic->evaluate(k * 1e-3, q, qd, qdd);
        check_position(q, s.start + k * 1e-3);
        for (std::size_t j = 0; j < design.joints.size(); ++j)
          if (std::abs(qd[j]) > design.joints[j].velocity)
            fail(j, s.start + k * 1e-3,
                 "moves at " + text(std::abs(qd[j])) + " rad/s, over its velocity limit " +
                     text(design.joints[j].velocity) + " rad/s");
      }
      continue;
    }
    if (!s.profile.moves()) continue;
    const double peak = s.profile.peak_velocity();
    for (std::size_t j = 0; j < design.joints.size(); ++j) {
      const double speed = std::abs(s.to[j] - s.from[j]) * peak;
      if (speed > design.joints[j].velocity)
        fail(j, s.start + s.profile.ramp,
             "moves at " + text(speed) + " rad/s, over its velocity limit " + text(design.joints[j].velocity) +
                 " rad/s");
    }
  }
}

}  // namespace symoro::trajectory
