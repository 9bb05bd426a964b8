// dynid export's options and its entry: a thin part per model of each robot (any variant:
// --model) in generated units (dynid_export-inl.hpp), or a loaded robot's library; the body once.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "dynid_dispatch.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::dynid {

struct ExportOptions {
  std::string study, urdf, model, prior, data;
  std::string into;  // the user's URDF to write the inertials into (dynid_urdf_into.hpp)
  // Strictly inside the consistent set, above rounding: a singular pseudo-inertia (lambda_min
  // -2e-17 measured with 0) is a body some simulators reject.
  double margin = 1e-9;
  int trial = 1;
  bool not_accepted = false, nearest = false;
  bool force = false;  // overwrite the URDF and its .standard files
};

// The prior's standard parameters from the robot's twin.yaml (its CAD truth); empty for a robot
// without a compiled twin.
using TwinPrior = std::function<Eigen::VectorXd(const twin::TwinConfig&)>;

struct ExportCommand {
  using Options = ExportOptions;
  // Per model (dynid_export-inl.hpp): hands the models to run_model.
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
  // The body, compiled once (dynid_export.cpp): the study's accepted base vector -> the physically
  // consistent standard parameters nearest the prior that map onto it exactly -> URDF +
  // standard-parameter YAML/CSV. parent: the robot's full model (the fitting run's regression).
  static void run_model(const Common& common, const Options& o,
                        const std::shared_ptr<const identify::IdentificationModel>& model,
                        const std::shared_ptr<const identify::IdentificationModel>& parent, const TwinPrior& twin_prior);
};

const CommandTable<ExportOptions>& export_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
