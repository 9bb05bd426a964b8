// dynid import's options and its entry, compiled for each robot's identified model (its joints
// name and type the columns) in generated units; the body is in dynid_import-inl.hpp.
#pragma once

#include <string>
#include <vector>

#include "dynid_dispatch.hpp"

namespace symoro::dynid {

struct ImportOptions {
  std::vector<std::string> inputs, names, heldout;
  std::string out, mapping, time, q, qd, tau, q_ref, qd_ref, qdd_ref;
  std::string time_unit, angle, header, delimiter;
  double torque_scale = 0, split = 0;
  bool allow_implausible = false;
};

struct ImportCommand {
  using Options = ImportOptions;
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
};

const CommandTable<ImportOptions>& import_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
