// load_robot runs its three stages (load/stages.hpp): read, check, lower.
#include "symoro/codegen/robot_model.hpp"

#include "load/stages.hpp"

namespace symoro::codegen {

RobotModel load_robot(const std::string& dir) {
  RobotModel m;
  const load::RobotFiles files = load::read_robot_folder(dir, m);
  const load::ParameterNames names = load::check_robot(files, m);
  load::lower_robot(files, names, m);
  return m;
}

}  // namespace symoro::codegen
