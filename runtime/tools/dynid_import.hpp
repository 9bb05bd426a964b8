// dynid import's options and its body: the exported logs mapped onto the robot's identified
// model's joints (they name and type the columns).
#pragma once

#include <string>
#include <vector>

#include "dynid_common.hpp"

namespace symoro::dynid {

struct ImportOptions {
  std::vector<std::string> inputs, names, heldout;
  std::string out, mapping, time, q, qd, tau, q_ref, qd_ref, qdd_ref;
  std::string time_unit, angle, header, delimiter;
  double torque_scale = 0, split = 0;
  // ROS 2 bags
  std::string topic = "/joint_states", stamp = "header", effort = "torque";
  std::vector<double> torque_constants;
  bool allow_implausible = false;
};

void run_import(const Common& common, const ImportOptions& options, const std::vector<JointInfo>& joints);

}  // namespace symoro::dynid
