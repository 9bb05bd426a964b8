#include "symoro/twin/simulator.hpp"

namespace symoro::twin {

control::FfpdGains controller_gains(const TwinConfig& c) { return c.controller.gains(); }

}  // namespace symoro::twin
