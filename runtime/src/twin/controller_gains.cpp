#include "symoro/twin/simulator.hpp"

namespace symoro::twin {

control::FfpdGains controller_gains(const TwinConfig& c) {
  const ControllerConfig& k = c.controller;
  return control::FfpdGains::from_bandwidth(k.period, k.pseudo_derivative_time, k.realization_inertia,
                                            k.realization_damping, k.bandwidth, k.damping_ratio);
}

}  // namespace symoro::twin
