// libFuzzer entry point for a dataset folder's manifest (io::read_dataset on the input as
// dataset.yaml, in a folder holding a valid log a.csv), then each run's window of that log
// (io::read_run_log). Any input must either read or throw DataError; a run read has its
// window's samples only. Another exception, a crash, a sanitizer report or a hang is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/error.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/log.hpp"

using symoro::fuzz::check;

namespace {

// a.csv: 5 samples at 0, 0.001, ..., 0.004 s of 2 joints.
const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    namespace io = symoro::io;
    const std::filesystem::path d = symoro::fuzz::scratch() / "dataset";
    std::filesystem::create_directories(d);
    io::Log log;
    log.meta.robot = "arm2";
    log.meta.trajectory = "a";
    log.meta.source = "robot";
    log.meta.sample_time = 0.001;
    log.meta.joints = {"j1", "j2"};
    log.time = Eigen::VectorXd::LinSpaced(5, 0, 0.004);
    log.q = log.qd = log.tau = Eigen::MatrixXd::Ones(5, 2);
    io::write_log(d / "a.csv", log);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  const fs::path& dir = folder();
  symoro::fuzz::write_bytes(dir / "dataset.yaml", std::string_view(reinterpret_cast<const char*>(data), size));
  try {
    const symoro::io::Dataset d = symoro::io::read_dataset(dir);
    int read = 0;
    for (const symoro::io::DatasetRun& run : d.runs) {
      // Only the folder's own log: a manifest may name any path (/dev/zero would never end).
      if (run.file != fs::absolute(dir / "a.csv") || ++read > 8) continue;
      try {
        const symoro::io::Log log = symoro::io::read_run_log(run);
        check(log.samples() >= 1 && log.samples() <= 5);
        for (Eigen::Index k = 0; k < log.samples(); ++k)
          check(run.window_start <= log.time[k] && log.time[k] < run.window_end);
      } catch (const symoro::DataError&) {
      }
    }
  } catch (const symoro::DataError&) {
  }
  return 0;
}
