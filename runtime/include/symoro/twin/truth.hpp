// The twin's true parameters for a robot model: standard parameters from the CAD chain (plus the
// payload when enabled), base parameters through the model's base_from_standard, and the
// link-side parameters used when backlash separates the rotors from the links. Any model of a
// robot (the full one, or a variant: its own standard parameter list) through its ModelHandle.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "symoro/robot/model_handle.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/standard_parameters.hpp"

namespace symoro::twin {

struct Truth {
  std::vector<LinkInertial> links;  // per model frame, with the payload
  Eigen::VectorXd standard;         // ns; Coulomb (FS) is 0: the twin applies its own
  Eigen::VectorXd phi;              // np; rigid drives: rotor inertia and viscous friction in the model
  Eigen::VectorXd phi_links;        // the same without rotor and viscous terms of backlash joints
};

// The last frame that carries a mass parameter: where a payload goes (0: none).
int payload_frame(const robot::ModelHandle& model);

// DataError (naming c.path) when the chain does not map onto the model's frames, or the model
// cannot represent the twin's truth.
Truth make_truth(const robot::ModelHandle& model, const TwinConfig& c);

// The twin's true identified parameters of a model (any variant): its base parameters plus what
// the variant's extra parameters can represent of the twin's hidden effects. Coulomb friction
// (FS or the smooth FC, the twin's smoothed Coulomb torque) and offsets (OFFj = minus the twin's
// external offset torque: the motor's holding torque); every other effect parameter is 0.
Eigen::VectorXd identified_truth(const robot::ModelHandle& model, const TwinConfig& c);

}  // namespace symoro::twin
