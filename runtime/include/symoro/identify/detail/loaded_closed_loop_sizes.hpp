// The loaded closed loop (loaded_closed_loop.hpp) at run-time sizes whatever the joint count: what
// a robot of 1 or more than 8 joints runs, for the tests to check on the shipped robots.
#pragma once

#include <memory>

#include "symoro/identify/closed_loop.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::identify::detail {

std::unique_ptr<ClosedLoop> closed_loop_run_time_sizes(const robot::ModelHandle& model, const ClosedLoopSetup& setup,
                                                       const trajectory::SampledReference& reference);

}  // namespace symoro::identify::detail
