#include "symoro/study/robot_folder.hpp"

#include <string>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/control/description.hpp"
#include "symoro/error.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::study {

ClosedLoopSource closed_loop_source(const std::filesystem::path& robot_dir, const identify::ModelDescription& model,
                                    const std::filesystem::path& design) {
  ClosedLoopSource loop;
  const auto controller_path = robot_dir / control::controller_file_name();
  if (std::filesystem::exists(controller_path))
    loop.setup = identify::closed_loop_setup(control::read_controller_description(controller_path, model.nq));
  else
    loop.why = fmt::format("no controller description ({} not found)", controller_path.string());
  const auto design_path = design.empty() ? robot_dir / "trajectories.yaml" : design;
  if (std::filesystem::exists(design_path)) loop.design = trajectory::TrajectoryDesign::read(design_path, model.joints);
  return loop;
}

bool nominal_standard_parameters(const std::filesystem::path& robot_dir,
                                 const std::vector<StandardParameterInfo>& standard, std::vector<double>& values) {
  const std::filesystem::path yaml = robot_dir / "robot.yaml";
  YAML::Node nominal;
  try {
    nominal = io::load_yaml_file(yaml)["nominal"];
  } catch (const YAML::Exception& e) {
    throw DataError(yaml.string(), e.mark.line + 1, e.msg);
  }
  if (!nominal || !nominal.IsMap()) return false;
  auto rigid = [](const std::string& f) {
    for (const char* r : {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FV", "FS"})
      if (f == r) return true;
    return false;
  };
  values.assign(standard.size(), 0.0);
  std::string missing;
  try {
    for (std::size_t i = 0; i < standard.size(); ++i) {
      if (const YAML::Node v = nominal[standard[i].name])
        values[i] = v.as<double>();
      else if (rigid(standard[i].family))
        missing += std::string(missing.empty() ? "" : ", ") + standard[i].name;
    }
  } catch (const YAML::Exception& e) {
    throw DataError(yaml.string(), e.mark.line + 1, e.msg);
  }
  if (!missing.empty()) throw DataError(yaml.string(), nominal.Mark().line + 1, "nominal lacks " + missing);
  return true;
}

}  // namespace symoro::study
