// dynid export --urdf --into <user.urdf>: identified inertials and joint dynamics written into
// the user's own URDF (the one symoroc model read, robot.yaml `urdf:`). Everything else of the
// file stays as it was, byte for byte: link and joint names, frames, visuals, collisions,
// meshes, comments, plugins. Only the chain links' <inertial> and the chain joints' <dynamics>
// change.
//
// Where symoroc model merged several URDF links into one model link (fixed joints, locked
// off-chain joints such as gripper fingers), the merged links keep their own (nominal)
// inertials and the chain link (the child of the chain joint) takes the rest of the identified
// body. When that rest is not physically consistent, the chain link takes the whole body and
// the merged links' inertials are removed; the output says so. Either way the file reproduces
// the identified standard parameters of every model link, and so the base parameters.
#pragma once

#include <string>
#include <vector>

#include "symoro/model_export/urdf_export.hpp"

namespace symoro::dynid {

// `robot_yaml` gives the `urdf:` section (file, base_link, joints, links, locked,
// frame0_in_base); `user_urdf` is the file to write into (its text is read here). Returns the
// new text; `notes` gets what the user should know. Throws UsageError on a file that is not the
// robot's (a chain joint or link missing) and DataError on malformed input.
std::string urdf_into(const model_export::UrdfDescription& d, const std::string& robot_yaml,
                      const std::string& user_urdf, std::vector<std::string>& notes);

}  // namespace symoro::dynid
