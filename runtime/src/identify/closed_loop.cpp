#include "symoro/identify/closed_loop.hpp"

#include <fmt/format.h>

#include "symoro/twin/simulator.hpp"

namespace symoro::identify {

ClosedLoopSetup closed_loop_setup(const twin::TwinConfig& config, double pre_roll) {
  ClosedLoopSetup s;
  s.gains = twin::controller_gains(config);
  s.delay = config.controller.communication_delay;
  s.pre_roll = pre_roll;
  return s;
}

std::string Divergence::describe() const {
  if (!diverged) return "no divergence";
  if (joint >= 0) return fmt::format("diverged at t = {:.3f} s, joint {}: {}", time, joint + 1, reason);
  return fmt::format("diverged at t = {:.3f} s: {}", time, reason);
}

}  // namespace symoro::identify
