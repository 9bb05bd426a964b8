// The emitters of a model's headers, one per kind, each returning the header's text. They
// differ in what they compute and share the function form and helpers of ModelContext; the
// functions they write are counted into the context's summary, in the order generate_robot
// (generator.cpp) calls them.
#pragma once

#include <string>
#include <vector>

#include "model_context.hpp"

namespace symoro::codegen::generate {

// model.hpp: sizes, parameter tables, joints, frames, gravity (model_header.cpp).
std::string model_header(ModelContext& c);

// base_parameters.hpp: base_from_standard, to_parent, from_parent (base_parameters_header.cpp).
std::string base_parameters_header(ModelContext& c);

// regressor.hpp: the regressor and the fixed parameters' torque (regressor_header.cpp).
std::string regressor_header(ModelContext& c);

// The dynamic models, each one function of the robot's expressions with the fixed values and
// effects in (dynamics_headers.cpp): inverse_dynamics.hpp, nonlinear_effects.hpp,
// forward_dynamics.hpp.
std::string inverse_dynamics_header(ModelContext& c);
std::string nonlinear_effects_header(ModelContext& c);
std::string forward_dynamics_header(ModelContext& c);

// inertia.hpp: M(q; phi) and its parameter-linear basis (inertia_header.cpp), which comes from
// the DIM's derivatives with respect to the accelerations: computed once for all the robot's
// models, before any is written, since the DIM must be linear in them.
std::string inertia_header(ModelContext& c);
DimDerivatives dim_derivatives(RobotModel& r);

// The derivative headers around derivative_functions.cpp (derivative_headers.cpp):
// inverse_dynamics_derivatives.hpp, forward_dynamics_derivatives.hpp, inertia_derivatives.hpp.
std::string inverse_dynamics_derivatives_header(ModelContext& c);
std::string forward_dynamics_derivatives_header(ModelContext& c);
std::string inertia_derivatives_header(ModelContext& c);

// The kinematic models (kinematics_headers.cpp): forward_kinematics.hpp, jacobian.hpp.
std::string forward_kinematics_header(ModelContext& c);
std::string jacobian_header(ModelContext& c);

// all.hpp: every header of the model, and `Model`, the type that names it (all_header.cpp).
std::string all_header(const ModelContext& c);

// <robot>.hpp: the robot's full model and variants, IdentifiedModel and Models (robot_header.cpp).
std::string robot_header(const RobotModel& r, const ModelContext& full, const std::vector<ModelContext>& variants);

}  // namespace symoro::codegen::generate
