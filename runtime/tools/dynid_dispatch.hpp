// Which (robot, model) instantiations of a dynid command this build holds. Each one is compiled
// in its own generated translation unit (units/*.cpp), which adds itself to its command's table
// (dynid_tables.cpp, generated); a command's own .cpp looks the robot up here and includes no
// robot header.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "dynid_common.hpp"

namespace symoro::dynid {

// The robots of robots/ this dynid was built with, in folder order (generated).
const std::vector<std::string>& robot_names();

// The files a robot's code was generated from, with their digests (generated/<robot>/source.hpp,
// gathered in the generated dynid_tables.cpp).
struct SourceFile {
  const char* name;
  const char* digest;
};
std::vector<SourceFile> robot_sources(const std::string& robot);

// Refuses (UsageError) a robot folder (--robots-dir/<robot>) whose robot.yaml or model files
// differ from those this dynid was compiled from: the compiled copy would be used silently.
void check_robot_folder(const Common& common);

// Whether common.robot is one this dynid was compiled with, from the folder it was compiled from
// (a --robot folder elsewhere is loaded from its library, even under a compiled robot's name).
bool compiled_robot(const Common& common);

// The error of a command that needs a robot compiled into dynid (the twin, the controller, the
// diagnosis and the export still do), for one that is not.
std::string not_compiled(const Common& common);

template <class Options>
class CommandTable {
 public:
  using Run = void (*)(const Common&, const Options&);

  // model: the variant label ("full" for the full model); "" for the robot's identified model,
  // or the one instantiation of a command compiled for a single model of each robot.
  void add(std::string robot, std::string model, Run run) { entries_.push_back({std::move(robot), std::move(model), run}); }

  // The command for common.robot (compiled for its full or identified model only).
  Run robot(const Common& common) const {
    if (!compiled_robot(common)) throw UsageError(not_compiled(common));
    for (const auto& e : entries_)
      if (e.robot == common.robot && e.model.empty()) {
        check_robot_folder(common);
        return e.run;
      }
    throw UsageError(not_compiled(common));
  }

  // The command for common.robot's model named `model` (a robot.yaml variant, or "full"; empty:
  // robot.yaml's `identified`); a usage error naming the robot's models if it has none such.
  Run model(const Common& common, const std::string& model) const {
    if (!compiled_robot(common)) throw UsageError(not_compiled(common));
    std::string list;
    for (const auto& e : entries_) {
      if (e.robot != common.robot) continue;
      if (e.model == model) {
        check_robot_folder(common);
        return e.run;
      }
      if (!e.model.empty()) list += (list.empty() ? "" : ", ") + e.model;
    }
    if (list.empty()) throw UsageError(not_compiled(common));
    throw UsageError("robot '" + common.robot + "' has no compiled model '" + model + "' (it has: " + list +
                     "); a variant just added to robot.yaml must be generated (symoroc generate robots/" + common.robot +
                     " -o generated) and dynid rebuilt");
  }

 private:
  struct Entry {
    std::string robot, model;
    Run run;
  };
  std::vector<Entry> entries_;
};

}  // namespace symoro::dynid
