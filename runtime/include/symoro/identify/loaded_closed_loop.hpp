// The closed loop (closed_loop.hpp) of a robot model loaded at run time: ClosedLoopSimulator's
// integration and sensitivities (detail/closed_loop_model.hpp) over a ModelHandle, in dynamic
// sizes. Its numbers agree with the generated model's simulator to round-off (the products and
// the factorization run in dynamic-size Eigen), not bit for bit (test_identify_loaded).
#pragma once

#include <memory>

#include "symoro/identify/closed_loop.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::identify {

std::unique_ptr<ClosedLoop> closed_loop(const robot::ModelHandle& model, const ClosedLoopSetup& setup,
                                        const trajectory::SampledReference& reference);

}  // namespace symoro::identify
