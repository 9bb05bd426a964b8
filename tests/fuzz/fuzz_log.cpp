// libFuzzer entry point for the log reader (io::read_log): the input is a CSV, or a sidecar and
// a CSV separated by a line "#csv" (without it, the sidecar is a valid one for 2 joints). Any
// input must either read or throw DataError; a log it reads writes and reads back bit for bit.
// Another exception, a crash, a sanitizer report or a hang is a bug.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/error.hpp"
#include "symoro/io/log.hpp"

using symoro::fuzz::check;

namespace {

constexpr std::string_view default_sidecar =
    "format: symoro-log 1\nrobot: arm2\ntrajectory: fuzz\ntrial: 1\nsource: robot\nsample_time: 0.001\n"
    "samples: 3\njoints: [j1, j2]\nunits:\n  time: s\n  q: rad\n  qd: rad/s\n  tau: N*m\n  q_ref: rad\n"
    "  qd_ref: rad/s\n  qdd_ref: rad/s^2\n";

bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), static_cast<std::size_t>(a.size()) * sizeof(double)) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = symoro::io;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find("\n#csv\n");
  const std::string_view sidecar = split == std::string_view::npos ? default_sidecar : input.substr(0, split + 1);
  const std::string_view csv = split == std::string_view::npos ? input : input.substr(split + 6);
  const auto path = symoro::fuzz::scratch() / "log.csv";
  symoro::fuzz::write_bytes(path, csv);
  symoro::fuzz::write_bytes(io::metadata_path(path), sidecar);
  io::Log log;
  try {
    log = io::read_log(path);
  } catch (const symoro::DataError&) {
    return 0;
  }
  // What was read writes and reads back exactly.
  const auto again = symoro::fuzz::scratch() / "again.csv";
  io::write_log(again, log);
  const io::Log back = io::read_log(again);
  check(same_bits(back.time, log.time) && same_bits(back.q, log.q) && same_bits(back.qd, log.qd) &&
        same_bits(back.tau, log.tau) && same_bits(back.q_ref, log.q_ref) && same_bits(back.qdd_ref, log.qdd_ref));
  check(back.meta.joints == log.meta.joints && back.meta.robot == log.meta.robot);
  return 0;
}
