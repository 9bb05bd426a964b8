// libFuzzer entry point for the importer's reader (io::import_log, then check_plausible): the
// first byte picks the mapping (by position or by header names, with or without references and
// velocity), the units, the delimiter and a prismatic second joint; the rest is the exported
// file. Any input must either import or throw DataError; an imported log has increasing time,
// one input line per row and finite values. Another exception, a crash, a sanitizer report or
// a hang is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/error.hpp"
#include "symoro/io/import.hpp"

using symoro::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = symoro::io;
  if (size == 0) return 0;
  const std::uint8_t pick = data[0];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  io::ImportMapping m;
  switch (pick & 3) {
    case 0:
      m.time = "1", m.q = "2-3", m.tau = "4,5";
      break;
    case 1:
      m.time = "t", m.q = "pos_*", m.qd = "vel_%", m.tau = "eff_*";
      break;
    case 2:
      m.time = "1", m.q = "2,3", m.tau = "4-5", m.q_ref = "6-7", m.qd_ref = "8-9", m.qdd_ref = "10-11";
      break;
    default:
      m.time = "time", m.q = "{name}_pos", m.tau = "e1,e2";
      break;
  }
  m.time_unit = static_cast<io::TimeUnit>((pick >> 2) & 3);
  m.angle_unit = (pick >> 4) & 1 ? io::AngleUnit::deg : io::AngleUnit::rad;
  m.delimiter = static_cast<io::Delimiter>((pick >> 5) & 3);
  io::ImportTarget target{"arm2", {"a", "b"}, {false, (pick >> 7) != 0}, {-2.8, 0.2}, {2.8, 0.9}};
  const auto path = symoro::fuzz::scratch() / "export.csv";
  symoro::fuzz::write_bytes(path, text);
  try {
    const io::ImportedLog imported = io::import_log(path, m, target);
    const io::Log& log = imported.log;
    check(log.samples() >= 2 && imported.lines.size() == static_cast<std::size_t>(log.samples()));
    for (Eigen::Index k = 1; k < log.samples(); ++k) check(log.time[k] > log.time[k - 1]);
    check(log.q.allFinite() && log.qd.allFinite() && log.tau.allFinite() && log.meta.sample_time > 0);
    io::check_plausible(imported, m, target);
  } catch (const symoro::DataError&) {
  }
  return 0;
}
