// The robot folder a command reads (--robots-dir/<robot>) against the one its code was compiled
// from: an edited robot.yaml (new limits, a new variant) or model file is refused, where the
// compiled copy used to be used silently.
#include <filesystem>

#include <fmt/format.h>

#include "dynid_robots.hpp"
#include "symoro/error.hpp"
#include "symoro/study/robot_folder.hpp"
#include "symoro/io/digest.hpp"

namespace symoro::dynid {

void check_robot_folder(const Common& common) {
  const std::filesystem::path dir = common.robot_dir();
  if (!std::filesystem::is_directory(dir))
    throw UsageError(fmt::format("robot '{}': {} is not a folder (--robots-dir)", common.robot, dir.string()));
  for (const SourceFile& f : robot_sources(common.robot)) {
    const std::filesystem::path file = dir / f.name;
    if (!std::filesystem::exists(file))
      throw UsageError(
          fmt::format("{} is missing: robot '{}' was compiled from a folder that has it", file.string(), common.robot));
    const std::string now = io::file_digest(file);
    if (now != f.digest)
      throw UsageError(
          fmt::format("{} differs from the {} robot '{}' was compiled from (digest {}, compiled {}): this "
                      "dynid would use the compiled copy; regenerate (symoroc generate {} -o generated) and "
                      "rebuild, or point --robots-dir at the folder it was compiled from",
                      file.string(), f.name, common.robot, now, f.digest, dir.string()));
  }
}

bool nominal_standard_parameters(const Common& common, const std::vector<StandardParameterInfo>& standard,
                                 std::vector<double>& values) {
  return study::nominal_standard_parameters(common.robot_dir(), standard, values);
}

}  // namespace symoro::dynid
