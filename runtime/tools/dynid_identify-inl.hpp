// dynid identify for one model (included by the generated units only): the model's
// IdentificationModel (compiled once, in symoro::<robot>_identification) and its twin truth,
// handed to the body compiled once (dynid_identify.cpp).
#pragma once

#include <Eigen/Core>

#include "dynid_identify.hpp"
#include "symoro/identify/identification_model.hpp"  // defined in symoro::<robot>_identification
#include "symoro/twin/truth.hpp"

namespace symoro::dynid {

template <class Full, class Model>
void IdentifyCommand::run(const Common& common, const IdentifyOptions& o) {
  if (o.take_model) return o.take_model(identify::identification_model<Model>());
  run_model(common, o, identify::identification_model<Model>(),
            [](const twin::TwinConfig& c) -> Eigen::VectorXd { return twin::identified_truth<Model>(c); });
}

}  // namespace symoro::dynid
