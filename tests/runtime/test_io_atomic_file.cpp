// Atomic writes: a temporary file left by a writer killed mid-write is removed by the next write
// of the same target once its process is gone, never while it lives; failures name the system's
// reason (a rename onto a directory, a full disk) and say whether a previous file is kept.
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "symoro/error.hpp"
#include "symoro/io/atomic_file.hpp"

namespace fs = std::filesystem;
using symoro::DataError;
using symoro::io::AtomicFile;
using symoro::io::write_file_atomically;
using symoro::io::write_files_atomically;

namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void touch(const fs::path& p) { std::ofstream(p) << "partial"; }

class AtomicFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("symoro_atomic_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (mounted_) ::umount(dir_.c_str());
    if (limited_) {
      ::setrlimit(RLIMIT_FSIZE, &saved_limit_);
      std::signal(SIGXFSZ, saved_handler_);
    }
    fs::remove_all(dir_);
  }
  // A disk that holds 64 KiB: a tmpfs on the test's folder when the test may mount one (root),
  // else the file size limit (RLIMIT_FSIZE, SIGXFSZ ignored), which fails a write past 64 KiB
  // the same way with EFBIG. The reason a failed write gives is returned.
  std::string small_disk() {
    mounted_ = ::geteuid() == 0 && ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
    if (mounted_) return "no space left on device";
    EXPECT_EQ(::getrlimit(RLIMIT_FSIZE, &saved_limit_), 0);
    saved_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = saved_limit_;
    small.rlim_cur = 64 << 10;
    EXPECT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
    limited_ = true;
    return std::strerror(EFBIG);
  }
  // The message of the DataError `f` throws ("" when it does not).
  template <class F>
  static std::string error_of(F f) {
    try {
      f();
    } catch (const DataError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
  bool mounted_ = false, limited_ = false;
  struct rlimit saved_limit_ {};
  void (*saved_handler_)(int) = SIG_DFL;
};

// A process that has exited and been reaped: its pid is no longer alive.
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

}  // namespace

// A writer killed (kill -9 during a 412 MB import) leaves its temporary file: the next write into
// the folder removes it, whatever file it was for, and never a live writer's or another host's.
TEST_F(AtomicFiles, TheNextWriteIntoTheFolderRemovesItsDeadWritersTemporaryFiles) {
  const fs::path target = dir_ / "big.csv";
  const pid_t dead = dead_pid();
  // A live process other than this one: a child waiting on a pipe until the test ends.
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t live = ::fork();
  if (live == 0) {
    char c;
    ::close(pipe_fds[1]);
    while (::read(pipe_fds[0], &c, 1) < 0) {
    }
    ::_exit(0);
  }
  ::close(pipe_fds[0]);

  const fs::path stale = AtomicFile::temp_path(target, dead, 0);
  const fs::path stale_later = AtomicFile::temp_path(target, dead, 12);
  const fs::path mine = AtomicFile::temp_path(target, ::getpid(), 9999);
  const fs::path living = AtomicFile::temp_path(target, live, 0);
  const fs::path other_target = AtomicFile::temp_path(dir_ / "other.csv", dead, 0);
  const fs::path other_host = dir_ / (".big.csv.symoro-tmp.another-host." + std::to_string(dead) + ".0");
  const fs::path not_ours = dir_ / (".big.csv.symoro-tmp.x." + std::to_string(dead));
  const fs::path no_pid = AtomicFile::temp_path(target, 4294967296L + dead, 0);  // wraps to `dead` as an int
  const fs::path other_living = AtomicFile::temp_path(dir_ / "other.csv", live, 3);
  const fs::path dotted_target = AtomicFile::temp_path(dir_ / "run.2.csv", dead, 1);
  for (const fs::path& p :
       {stale, stale_later, mine, living, other_target, other_host, not_ours, no_pid, other_living, dotted_target})
    touch(p);
  EXPECT_EQ(stale.filename().string().rfind(".big.csv.symoro-tmp.", 0), 0u) << stale;

  write_file_atomically(target, "time\n");
  EXPECT_EQ(read_text(target), "time\n");
  for (const fs::path& p : {stale, stale_later, other_target, dotted_target}) EXPECT_FALSE(fs::exists(p)) << p;
  for (const fs::path& p : {mine, living, other_host, not_ours, no_pid, other_living}) EXPECT_TRUE(fs::exists(p)) << p;
  ::close(pipe_fds[1]);
  ::waitpid(live, nullptr, 0);
  // The write's own temporary file is gone too: the folder holds the target and the kept files.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir_)) {
    (void)e;
    ++entries;
  }
  EXPECT_EQ(entries, 7);  // the target and the six kept
}

TEST_F(AtomicFiles, AnAbandonedWriteLeavesNothing) {
  const fs::path target = dir_ / "a.yaml";
  {
    AtomicFile f(target);
    f.stream() << "half";
  }
  EXPECT_TRUE(fs::is_empty(dir_));
}

// rename() onto a directory fails with EISDIR: the message says so (it said "Success": the
// error code was overwritten by the clean-up before the message was built).
TEST_F(AtomicFiles, ARenameFailureNamesItsReason) {
  const fs::path target = dir_ / "taken";
  fs::create_directories(target / "inside");
  const std::string what = error_of([&] { write_file_atomically(target, "x\n"); });
  EXPECT_NE(what.find(target.string() + ": error: cannot rename the written file into place: Is a directory"),
            std::string::npos)
      << what;
  EXPECT_EQ(what.find("Success"), std::string::npos) << what;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// A full disk (small_disk). Without a previous file the message does not pretend one was kept;
// with one, it is kept as it was.
TEST_F(AtomicFiles, AFullDiskSaysSoAndWhetherAPreviousFileIsKept) {
  const std::string reason = small_disk();
  const fs::path target = dir_ / "big.csv";
  const std::string big(1 << 20, '1');
  std::string what = error_of([&] { write_file_atomically(target, big); });
  EXPECT_NE(what.find(target.string() + ": error: writing failed: " + reason + "; nothing is written under this name"),
            std::string::npos)
      << what;
  EXPECT_EQ(what.find("previous file"), std::string::npos) << what;
  EXPECT_TRUE(fs::is_empty(dir_));

  write_file_atomically(target, "time\n0\n");
  what = error_of([&] { write_file_atomically(target, big); });
  EXPECT_NE(what.find("writing failed: " + reason + "; the previous file is left as it was"), std::string::npos)
      << what;
  EXPECT_EQ(read_text(target), "time\n0\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// Files that belong together (dynid export: a URDF and its .standard.yaml and .csv) are written all
// or none: on a full disk (small_disk) the URDF was written without the other two, and the rerun
// refused.
TEST_F(AtomicFiles, AGroupIsWrittenAllOrNone) {
  const std::string reason = small_disk();
  const fs::path urdf = dir_ / "arm.urdf", yaml = dir_ / "arm.standard.yaml", csv = dir_ / "arm.standard.csv";
  write_files_atomically({{urdf, "<robot/>\n"}, {yaml, "a: 1\n"}, {csv, "a,1\n"}});
  EXPECT_EQ(read_text(urdf), "<robot/>\n");
  EXPECT_EQ(read_text(yaml), "a: 1\n");
  EXPECT_EQ(read_text(csv), "a,1\n");

  // The last file does not fit: none of the three changes, and no temporary file stays.
  const std::string what = error_of([&] {
    write_files_atomically({{urdf, "<robot name='b'/>\n"}, {yaml, "a: 2\n"}, {csv, std::string(1 << 20, '2')}});
  });
  EXPECT_NE(what.find(": error: writing failed: " + reason), std::string::npos) << what;
  EXPECT_EQ(read_text(urdf), "<robot/>\n");
  EXPECT_EQ(read_text(yaml), "a: 1\n");
  EXPECT_EQ(read_text(csv), "a,1\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 3);
}
