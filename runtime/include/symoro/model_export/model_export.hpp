// A study's accepted base parameters as a robot description (dynid export, symoro.export_urdf):
// the physically consistent standard parameters nearest a prior that reproduce them exactly
// (physical_consistency.hpp), checked independently of the solver (max |B s - phi|), as the
// URDF of urdf_export.hpp and the standard-parameter YAML/CSV beside it. Compiled once, through
// the model's IdentificationModel.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "symoro/identify/identification_model.hpp"
#include "symoro/model_export/urdf_export.hpp"

namespace symoro::model_export {

struct ModelExportOptions {
  Eigen::VectorXd prior;   // standard parameters (description().standard's order) the inertials lean to
  std::string prior_what;  // what the prior is, for the notes
  std::string study;       // the study folder, for the notes
  bool accepted = true;    // whether the study's final audit accepted phi (said in the notes)
  // Every link's pseudo-inertia >= margin I: strictly inside the consistent set, above rounding
  // (a singular pseudo-inertia is a body some simulators reject).
  double margin = 1e-9;
  // No consistent set reproduces phi: export the nearest base vector that has one (else throw).
  bool nearest = false;
  // The metric of "nearest" (ConsistencyOptions::base_metric_root; empty: the solver's own), and
  // a sentence on what the nearest vector costs in torque (given the target and the vector).
  Eigen::MatrixXd base_metric_root;
  std::function<std::string(const Eigen::VectorXd& target, const Eigen::VectorXd& nearest)> cost;
};

struct ModelExport {
  identify::ConsistencyResult consistency;
  bool nearest = false;         // the nearest consistent base vector was exported, not phi
  double residual = 0;          // max |B s - phi| (phi in the full model's base)
  std::string cost;             // ModelExportOptions::cost's sentence, when there is no consistent set
  UrdfDescription description;  // s and the provenance notes
  std::string header;           // the standard-parameter YAML's header
};

// Throws std::runtime_error ("no URDF written: ...") when no consistent set reproduces phi and
// not options.nearest, or the solve fails; std::logic_error for a model with effect parameters.
ModelExport export_model(const identify::IdentificationModel& model, const Eigen::VectorXd& phi,
                         const ModelExportOptions& options);

// Writes `urdf_text` to `urdf` and the standard parameters to <urdf stem>.standard.yaml and
// .standard.csv (each atomically, folders created); returns the three paths.
struct ModelExportFiles {
  std::filesystem::path urdf, yaml, csv;
};
ModelExportFiles write_model_export(const ModelExport& e, const std::filesystem::path& urdf,
                                    const std::string& urdf_text);

}  // namespace symoro::model_export
