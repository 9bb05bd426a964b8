// dynid import for one robot (included by the generated units only): its joints, handed to the
// body compiled once (dynid_import.cpp).
#pragma once

#include "dynid_import.hpp"

namespace symoro::dynid {

template <class Full, class Model>
void ImportCommand::run(const Common& common, const ImportOptions& o) {
  run_joints(common, o, joint_list<Model>());
}

}  // namespace symoro::dynid
