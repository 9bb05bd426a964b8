// dynid import's options and its entry: the robot's identified model's joints (they name and type
// the columns), from a generated unit (dynid_import-inl.hpp) or a loaded robot library.
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
  // The body, compiled once (dynid_import.cpp): the exported logs mapped onto these joints.
  static void run_joints(const Common& common, const Options& o, const std::vector<JointInfo>& joints);
};

const CommandTable<ImportOptions>& import_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
