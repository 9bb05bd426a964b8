// dynid export's options and its body, on the model of any robot whose study it exports.
#pragma once

#include <string>

#include "dynid_common.hpp"
#include "symoro/model_export/model_export.hpp"

namespace symoro::dynid {

struct ExportOptions {
  std::string study, urdf, model, prior, data;
  std::string mjcf;     // the MuJoCo model to write (model_export/mjcf_export.hpp)
  std::string into;     // the user's URDF to write the inertials into (dynid_urdf_into.hpp)
  std::string payload;  // a payload.yaml (dynid payload) added as a link on the flange
  // Strictly inside the consistent set, above rounding: a singular pseudo-inertia (lambda_min
  // -2e-17 measured with 0) is a body some simulators reject. The library's defaults.
  double margin = model_export::ModelExportOptions{}.margin;
  int trial = 1;
  bool not_accepted = false, nearest = model_export::ModelExportOptions{}.nearest;
  bool force = false;  // overwrite the URDF and its .standard files
};

// The study's accepted base vector of model `label` -> the physically consistent standard
// parameters nearest the prior (--prior; else the twin's CAD truth when the robot has a twin.yaml,
// else robot.yaml's nominal) that map onto it exactly -> URDF + standard-parameter YAML/CSV.
void run_export(const Common& common, const ExportOptions& options, const std::string& label);

}  // namespace symoro::dynid
