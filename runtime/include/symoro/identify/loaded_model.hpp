// IdentificationModel (identification_model.hpp) of a robot model loaded at run time
// (symoro/robot/robot_library.hpp): the study, the audit, the SDP and the physical path compiled
// once, calling the robot library's functions. Regressions, torques, inertia functions and the
// physical path equal the generated Model's (identification_model<Model>()) bit for bit: the same
// kernels, the same arithmetic around them; the closed loop (CLIE) to round-off
// (loaded_closed_loop.hpp).
#pragma once

#include <memory>

#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::identify {

// model: the model to identify; full: its robot's full model (the library's first), whose base
// the physical path and the export solve in.
std::shared_ptr<const IdentificationModel> identification_model(const robot::ModelHandle& model,
                                                                const robot::ModelHandle& full);

}  // namespace symoro::identify
