// libFuzzer entry point for the ROS 2 bag reader (io::import_bag over io::read_mcap and the
// JointState CDR decoder): the first byte picks the settings (the stamp source, the effort kind),
// the rest is the MCAP file. Any input must either import or throw DataError; an imported log has
// increasing time, one message number per row and finite values. Another exception, a crash, a
// sanitizer report or a hang is a bug. Seeds (corpus_mcap/): small bags of tests/bags/
// write_bag.mjs, lz4, zstd and uncompressed, chunked and not, joints a and b.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_files.hpp"
#include "symoro/error.hpp"
#include "symoro/io/import_bag.hpp"

using symoro::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = symoro::io;
  if (size == 0) return 0;
  const std::uint8_t pick = data[0];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  io::BagSettings s;
  s.stamp = pick & 1 ? io::StampSource::receive : io::StampSource::header;
  if (pick & 2) {
    s.effort = io::EffortKind::current;
    s.torque_constants = {2.0, 0.5};
  }
  io::ImportTarget target{"arm2", {"a", "b"}, {false, false}, {-2.8, -2.8}, {2.8, 2.8}};
  const auto path = symoro::fuzz::scratch() / "bag.mcap";
  symoro::fuzz::write_bytes(path, bytes);
  try {
    const io::ImportedLog imported = io::import_bag(path, s, target);
    const io::Log& log = imported.log;
    check(log.samples() >= 4 && imported.lines.size() == static_cast<std::size_t>(log.samples()));
    for (Eigen::Index k = 1; k < log.samples(); ++k) check(log.time[k] > log.time[k - 1]);
    check(log.q.allFinite() && log.qd.allFinite() && log.tau.allFinite() && log.meta.sample_time > 0);
  } catch (const symoro::DataError&) {
  }
  return 0;
}
