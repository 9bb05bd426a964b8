// dynid export for one model (included by the generated units only): its IdentificationModel
// and its full model's, and the twin's CAD truth as the prior, handed to the body compiled once
// (dynid_export.cpp).
#pragma once

#include <Eigen/Core>

#include "dynid_export.hpp"
#include "symoro/identify/identification_model.hpp"  // defined in symoro::<robot>_identification
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::dynid {

template <class Full, class Model>
void ExportCommand::run(const Common& common, const ExportOptions& o) {
  using Parent = typename Model::Parent;
  run_model(common, o, identify::identification_model<Model>(), identify::identification_model<Parent>(),
            [](const twin::TwinConfig& tc) -> Eigen::VectorXd { return twin::make_truth<Parent>(tc).standard; });
}

}  // namespace symoro::dynid
