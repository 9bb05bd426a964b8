// io::LogStream, the control loop's log: every flush leaves a readable log, and a stalled writer
// neither blocks the producer nor loses a row it accepted.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <symoro/io/log.hpp>
#include <symoro/io/log_stream.hpp>

#include "symoro/error.hpp"

namespace symoro::io {
namespace {

std::filesystem::path temp_dir() {
  const auto d = std::filesystem::temp_directory_path() / ("symoro_logstream_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

// A robot's log of two joints at 1 kHz.
LogMetadata two_joints() {
  LogMetadata meta;
  meta.robot = "crane_x7";
  meta.trajectory = "T";
  meta.source = "robot";
  meta.sample_time = 0.001;
  meta.joints = {"a", "b"};
  return meta;
}

TEST(LogStream, EveryFlushLeavesAReadableLog) {
  const auto dir = temp_dir();
  const auto csv = dir / "stream.csv";
  LogMetadata meta = two_joints();
  {
    LogStream s(csv, meta, true, std::chrono::milliseconds(10));
    const double v[2] = {0.5, -0.25};
    for (int k = 0; k < 50; ++k) ASSERT_TRUE(s.append(k * 0.001, v, v, v, v, v, v));
    EXPECT_FALSE(s.append(0.01, v, v, v, v, v, v));  // time must increase
    s.flush();
    const Log mid = read_log(csv);  // a reader in the middle of the run
    EXPECT_EQ(mid.samples(), 50);
    for (int k = 50; k < 80; ++k) s.append(k * 0.001, v, v, v, v, v, v);
    s.set_notes("done");
  }  // the destructor closes
  const Log log = read_log(csv);
  EXPECT_EQ(log.samples(), 80);
  EXPECT_EQ(log.meta.notes, "done");
  EXPECT_EQ(log.qd_ref(79, 1), -0.25);
  std::filesystem::remove_all(dir);
}

// The loop's side of the log never waits for the writer: with the writer stuck in write() (the
// CSV is a pipe nobody reads yet), append() goes on accepting rows into the queue until it is
// full and then drops and counts them; once the pipe is read, every accepted row is on disk, in
// order, and the count adds up.
TEST(LogStream, AStalledWriterNeitherBlocksAppendNorLosesAnAcceptedRow) {
  const auto dir = temp_dir();
  const auto csv = dir / "pipe.csv";
  ASSERT_EQ(::mkfifo(csv.c_str(), 0644), 0);
  std::atomic<bool> go{false};
  std::string text;
  std::thread reader([&] {
    const int fd = ::open(csv.c_str(), O_RDONLY);
    if (fd < 0) return;
    ::fcntl(fd, F_SETPIPE_SZ, 4096);  // a small pipe: the writer blocks early
    while (!go.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    char buf[4096];
    for (ssize_t r; (r = ::read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(r));
    ::close(fd);
  });
  LogMetadata meta;
  meta.robot = "crane_x7";
  meta.trajectory = "T";
  meta.source = "robot";
  meta.sample_time = 0.001;
  for (int j = 0; j < 10; ++j) meta.joints.push_back(fmt::format("j{}", j));
  constexpr int kCapacity = 16, kAttempts = 400;
  std::int64_t accepted = 0;
  {
    LogStream s(csv, meta, true, std::chrono::milliseconds(1), kCapacity);
    std::vector<double> v(10);
    for (int k = 0; k < kAttempts; ++k) {
      for (int j = 0; j < 10; ++j) v[j] = 0.123456789 * (k + 1) + j;  // ~900 bytes a row
      accepted += s.append(k * 0.001, v.data(), v.data(), v.data(), v.data(), v.data(), v.data());
      if (k % 16 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the writer drains, then sticks
    }
    EXPECT_EQ(s.appended(), accepted);
    EXPECT_EQ(s.appended() + s.overflowed(), kAttempts);
    // The writer holds at most a batch, the queue and what fits the pipe: the rest overflowed.
    EXPECT_GT(s.overflowed(), 0);
    EXPECT_LE(accepted, 2 * kCapacity + 8);
    go = true;  // the pipe is read; close() writes the rest
  }
  reader.join();
  // The text the pipe carried: header and one line per accepted row, times increasing.
  std::vector<std::string> lines;
  for (std::size_t a = 0, b; (b = text.find('\n', a)) != std::string::npos; a = b + 1)
    lines.push_back(text.substr(a, b - a));
  ASSERT_EQ(static_cast<std::int64_t>(lines.size()), accepted + 1);
  double previous = -1;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const double t = std::stod(lines[i].substr(0, lines[i].find(',')));
    EXPECT_GT(t, previous);
    previous = t;
    EXPECT_EQ(std::count(lines[i].begin(), lines[i].end(), ','), 60);
  }
  std::filesystem::remove_all(dir);
}

// A full disk (here the file size limit, RLIMIT_FSIZE, which fails a write as a full disk does,
// after a part of it) in the middle of a run: the CSV ends on its last whole row, the sidecar
// counts exactly those rows and says the log is incomplete and why, the rows after are counted
// as lost, and close() throws the reason. It used to end mid-number with a sidecar that counted
// rows the file did not hold.
TEST(LogStream, AFullDiskEndsTheLogOnItsLastWholeRowAndSaysSo) {
  const auto dir = temp_dir();
  const auto csv = dir / "full.csv";
  LogMetadata meta = two_joints();
  meta.notes = "run notes";
  struct rlimit saved {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);  // the write fails (EFBIG) instead
  constexpr rlim_t kLimit = 40'000;
  struct rlimit small = saved;
  small.rlim_cur = kLimit;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  constexpr int kRows = 2000;
  std::int64_t written = 0, lost = 0;
  std::string error;
  {
    LogStream s(csv, meta, true, std::chrono::milliseconds(5));
    const double v[2] = {0.123456789012, -9.87654321098};
    for (int k = 0; k < kRows; ++k) {
      ASSERT_TRUE(s.append(k * 0.001, v, v, v, v, v, v));
      if (k % 200 == 0) s.flush();
    }
    s.flush();
    EXPECT_TRUE(s.failed());
    try {
      s.close();
      ADD_FAILURE() << "close() did not say the log is short";
    } catch (const DataError& e) {
      error = e.what();
    }
    written = s.written();
    lost = s.lost();
  }
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, previous);
  EXPECT_NE(error.find("cannot write the log"), std::string::npos) << error;
  EXPECT_GT(written, 10);
  EXPECT_LT(written, kRows);
  EXPECT_EQ(written + lost, kRows);
  // The CSV: whole rows only, as many as the sidecar says, within the limit.
  std::ifstream in(csv, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  EXPECT_LE(text.size(), kLimit);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), written + 1);  // and the header
  const Log log = read_log(csv);
  EXPECT_EQ(log.samples(), written);
  EXPECT_EQ(log.time(written - 1), (written - 1) * 0.001);
  EXPECT_NE(log.meta.notes.find("run notes"), std::string::npos) << log.meta.notes;
  EXPECT_NE(log.meta.notes.find("LOG INCOMPLETE: cannot write the log"), std::string::npos) << log.meta.notes;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace symoro::io
