#include "symoro/identify/closed_loop.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "symoro/identify/detail/closed_loop_model.hpp"

namespace symoro::identify {

ClosedLoopSetup closed_loop_setup(const control::ControllerDescription& controller, double pre_roll) {
  ClosedLoopSetup s;
  s.gains = controller.gains();
  s.delay = controller.communication_delay;
  s.pre_roll = pre_roll;
  return s;
}

std::string Divergence::describe() const {
  if (!diverged) return "no divergence";
  if (joint >= 0) return fmt::format("diverged at t = {:.3f} s, joint {}: {}", time, joint + 1, reason);
  return fmt::format("diverged at t = {:.3f} s: {}", time, reason);
}

namespace detail {

namespace {

Divergence divergence(double time, int joint, std::string reason) {
  Divergence d;
  d.diverged = true;
  d.time = time;
  d.joint = joint;
  d.reason = std::move(reason);
  return d;
}

}  // namespace

Divergence tracking_divergence(double time, int joint, double error) {
  return divergence(time, joint, fmt::format("tracking error {:.3g} rad", error));
}

Divergence indefinite_inertia(double time, double smallest_pivot) {
  return divergence(time, -1, fmt::format("M not positive definite (smallest LDLT pivot {:.3g})", smallest_pivot));
}

Divergence not_finite(double time) { return divergence(time, -1, "state not finite"); }

void check_setup(const ClosedLoopSetup& s, int joints) {
  const control::FfpdGains& g = s.gains;
  if (g.inertia.size() != joints || g.damping.size() != joints || g.kp.size() != joints || g.kv.size() != joints)
    throw std::invalid_argument(fmt::format("closed-loop setup: the controller gains need {} entries each", joints));
  if (!(g.period > 0) || !(g.pseudo_derivative_time > 0))
    throw std::invalid_argument("closed-loop setup: period and pseudo-derivative time must be positive");
  // The command must take effect within its own cycle: the hold structure assumes it.
  if (!(s.delay >= 0) || !(s.delay < g.period))
    throw std::invalid_argument(
        fmt::format("closed-loop setup: delay {} s must be in [0, period = {} s)", s.delay, g.period));
  if (!(s.pre_roll >= 0) || s.substeps < 1 || !(s.divergence_error > 0))
    throw std::invalid_argument("closed-loop setup: pre_roll >= 0, substeps >= 1 and divergence_error > 0 needed");
}

}  // namespace detail

}  // namespace symoro::identify
