// The normalized point-to-point profile with sine-squared acceleration ramps.
//
// In the first ramp (0 <= u <= r) with peak acceleration A:
//   sdd = A sin^2(pi u / r),  sd = A (u/2 - r/(4 pi) sin(2 pi u / r)),
//   s   = A (u^2/4 - r^2/(4 pi^2) sin^2(pi u / r)),
// so the ramp ends at sd = V = A r / 2 and s = V r / 2. The cruise holds sd = V; the last ramp
// mirrors the first (s(T - u) = 1 - s(u)). The distance is V (r + cruise) = 1, hence
// V = 1 / (r + cruise) and A = 2 V / r: ramp and cruise describe the profile entirely.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "symoro/trajectory/trajectory.hpp"

namespace symoro::trajectory {

namespace {
constexpr double kPi = 3.14159265358979323846;

// The first ramp at time u from its start.
void first_ramp(double u, double ramp, double peak_acceleration, double& s, double& sd, double& sdd) {
  const double phase = kPi * u / ramp;
  const double sine = std::sin(phase);
  s = peak_acceleration * (0.25 * u * u - ramp * ramp / (4 * kPi * kPi) * sine * sine);
  sd = peak_acceleration * (0.5 * u - ramp / (4 * kPi) * std::sin(2 * phase));
  sdd = peak_acceleration * sine * sine;
}
}  // namespace

Profile Profile::plan(double velocity, double acceleration) {
  if (!(velocity > 0) || !(acceleration > 0) || !std::isfinite(velocity) || !std::isfinite(acceleration))
    throw std::invalid_argument("Profile::plan: velocity and acceleration limits must be positive");
  Profile p;
  // Two full ramps at the velocity limit cover V * r = 2 V^2 / A.
  if (2 * velocity * velocity / acceleration <= 1.0) {
    p.ramp = 2 * velocity / acceleration;
    p.cruise = 1.0 / velocity - p.ramp;
  } else {
    // Too short for a cruise: the peak velocity sqrt(A / 2) makes the two ramps cover 1.
    p.ramp = std::sqrt(2.0 / acceleration);
    p.cruise = 0;
  }
  p.duration = 2 * p.ramp + p.cruise;
  return p;
}

Profile Profile::hold(double duration) {
  Profile p;
  p.duration = duration;
  return p;
}

double Profile::peak_velocity() const { return moves() ? 1.0 / (ramp + cruise) : 0.0; }

double Profile::peak_acceleration() const { return moves() ? 2 * peak_velocity() / ramp : 0.0; }

void Profile::evaluate(double t, double& s, double& sd, double& sdd) const {
  if (!moves()) {
    s = sd = sdd = 0;
    return;
  }
  t = std::clamp(t, 0.0, duration);
  const double velocity = peak_velocity();
  const double acceleration = peak_acceleration();
  if (t <= ramp) {
    first_ramp(t, ramp, acceleration, s, sd, sdd);
  } else if (t <= ramp + cruise) {
    s = 0.5 * velocity * ramp + velocity * (t - ramp);
    sd = velocity;
    sdd = 0;
  } else {
    first_ramp(duration - t, ramp, acceleration, s, sd, sdd);
    s = 1.0 - s;
    sdd = -sdd;
  }
}

}  // namespace symoro::trajectory
