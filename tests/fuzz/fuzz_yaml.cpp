// libFuzzer entry point for the runtime's other YAML readers (dataset.yaml has fuzz_dataset): the
// input as an import mapping (io::read_import_mapping), as a parameters file (read_parameters_yaml,
// parameters_accepted, parameters_integrity) and as a log's sidecar (read_log_metadata). Any input
// must either read or throw DataError; another exception, a crash, a sanitizer report or a hang is
// a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/error.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/parameters_yaml.hpp"

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
  return 0;
}
