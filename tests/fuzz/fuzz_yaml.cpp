// libFuzzer entry point for the runtime's other YAML readers (dataset.yaml has fuzz_dataset): the
// input as an import mapping (io::read_import_mapping), as a parameters file (read_parameters_yaml,
// parameters_accepted, parameters_integrity), as a log's sidecar (read_log_metadata), as
// hardware.yaml, controller.yaml, twin.yaml and a trajectory design for a 2-joint arm, and as
// symoroc's robot.yaml. Any input must either read or throw DataError (InputError for robot.yaml);
// another exception, a crash, a sanitizer report or a hang is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/codegen/robot_spec.hpp"
#include "symoro/control/description.hpp"
#include "symoro/error.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/config.hpp"

namespace {

template <class Read>
void either_reads_or_refuses(Read read) {
  try {
    read();
  } catch (const symoro::DataError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  namespace io = symoro::io;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const fs::path dir = symoro::fuzz::scratch();
  const fs::path mapping = dir / "mapping.yaml", params = dir / "parameters.yaml", csv = dir / "log.csv";
  symoro::fuzz::write_bytes(mapping, bytes);
  symoro::fuzz::write_bytes(params, bytes);
  symoro::fuzz::write_bytes(io::metadata_path(csv), bytes);
  either_reads_or_refuses([&] { io::read_import_mapping(mapping); });
  const std::vector<std::string> names = {"ZZ1", "FV1", "FS1"};
  either_reads_or_refuses([&] {
    const Eigen::VectorXd phi = io::read_parameters_yaml(params.string(), names);
    symoro::fuzz::check(phi.size() == 3 && phi.allFinite());
  });
  either_reads_or_refuses([&] { io::parameters_accepted(params.string()); });
  either_reads_or_refuses([&] { io::parameters_integrity(params.string(), names); });
  either_reads_or_refuses([&] { io::read_log_metadata(csv); });
  const fs::path hardware = dir / "hardware.yaml", controller = dir / "controller.yaml", twin = dir / "twin.yaml";
  for (const fs::path& f : {hardware, controller, twin}) symoro::fuzz::write_bytes(f, bytes);
  const std::vector<symoro::JointInfo> joints = {{"j1", symoro::JointType::Revolute, -2, 2, 3, 10, -2, 2},
                                                 {"j2", symoro::JointType::Prismatic, 0, 0.2, 1, 50, 0, 0.2}};
  either_reads_or_refuses([&] { symoro::hardware::read_hardware_config(hardware, joints); });
  either_reads_or_refuses([&] { symoro::control::read_controller_description(controller, 2); });
  either_reads_or_refuses([&] { symoro::twin::read_twin_config(twin, 2); });
  const fs::path design = dir / "trajectories.yaml", robot = dir / "robot.yaml";
  symoro::fuzz::write_bytes(design, bytes);
  either_reads_or_refuses([&] { symoro::trajectory::TrajectoryDesign::read(design, joints); });
  symoro::fuzz::write_bytes(robot, bytes);
  try {
    symoro::codegen::read_robot_spec(robot.string());
  } catch (const symoro::codegen::InputError&) {
  }
  return 0;
}
