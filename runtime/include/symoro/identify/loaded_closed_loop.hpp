// The closed loop (closed_loop.hpp) of any robot model through its ModelHandle: ClosedLoopSimulator's
// integration and sensitivities (detail/closed_loop_model.hpp), at compile-time joint counts 2 to 8
// and run-time sizes otherwise. Its numbers equal the generated model's fixed-size simulator bit
// for bit (the products and the inertia solve are plain loops in one order; test_identify_loaded).
#pragma once

#include <memory>

#include "symoro/identify/closed_loop.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::identify {

std::unique_ptr<ClosedLoop> closed_loop(const robot::ModelHandle& model, const ClosedLoopSetup& setup,
                                        const trajectory::SampledReference& reference);

}  // namespace symoro::identify
