// dynid export's options and its entry, compiled per model of each robot (any variant:
// --model) in generated units; the body is in dynid_export-inl.hpp.
#pragma once

#include <string>

#include "dynid_dispatch.hpp"

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

struct ExportCommand {
  using Options = ExportOptions;
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
};

const CommandTable<ExportOptions>& export_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
