// The kinematic models of the last arm frame: its pose (fgm.txt) and Jacobian (jac.txt).
#include "headers.hpp"

namespace symoro::codegen::generate {

std::string forward_kinematics_header(ModelContext& c) {
  std::string s = c.banner("Forward kinematics of the last arm frame (fgm.txt).");
  s += c.kinematic_includes() + c.open();
  s += c.function("// The 4 x 4 homogeneous pose of frame " + str(c.r.fgm_frame) + " in frame 0.\n",
                  "forward_kinematics", {c.q_in()}, {"T", "4", "4", c.r.fgm});
  s += c.close();
  return s;
}

std::string jacobian_header(ModelContext& c) {
  std::string s = c.banner("Jacobian of the last arm frame (jac.txt).");
  s += c.kinematic_includes() + c.open();
  s += c.function("// The 6 x nq Jacobian of frame " + str(c.r.fgm_frame) +
                      " projected in frame 0: linear velocity rows first, then angular.\n",
                  "jacobian", {c.q_in()}, {"J", "6", "nq", c.r.jac});
  s += c.close();
  return s;
}

}  // namespace symoro::codegen::generate
