// Atomic file output: the content goes to a temporary file next to the target, is flushed to
// disk, and is renamed over the target only when complete. A crash or an error never leaves a
// half-written file under the target name, and never destroys the file that was there.
//
// The temporary file is ".<name>.symoro-tmp.<host>.<pid>.<n>" (hidden, and recognisable): a
// process killed while writing leaves it behind, and the next atomic write into the same folder
// removes it once its writer is gone (same host, kill(pid, 0) says no such process), whatever
// file it was for. A live writer's file, or another host's (a shared folder), is never touched.
#pragma once

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace symoro::io {

class AtomicFile {
 public:
  // Removes the stale temporary files of the target's folder, then opens a new one for writing;
  // throws DataError when it cannot.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Removes the temporary file if commit() was not called.
  ~AtomicFile();

  std::ostream& stream() { return out_; }
  // Flushes and fsyncs the temporary file; throws DataError on any failure (the temporary file
  // is then removed and the target untouched), naming the system's reason ("no space left on
  // device", ...). commit() does it first when it was not called.
  void finish();
  // finish(), then renames over the target; throws DataError on any failure (the target is then
  // untouched).
  void commit();

  // The temporary file's name for `target` written by process `pid`, write number `n`.
  static std::filesystem::path temp_path(const std::filesystem::path& target, long pid, unsigned n);

 private:
  class Buffer;
  std::filesystem::path target_, temp_;
  std::unique_ptr<Buffer> buffer_;
  std::ostream out_;
  bool finished_ = false, committed_ = false;
};

// Writes `content` to `target` atomically.
void write_file_atomically(const std::filesystem::path& target, const std::string& content);

// Writes files that belong together (a URDF and its parameter files) all or none: each is
// complete on disk before any takes its name, so a failure (a full disk) leaves every target as
// it was. Only the renames that follow are one by one.
void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string>>& files);

}  // namespace symoro::io
