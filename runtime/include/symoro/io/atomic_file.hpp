// Atomic file output: the content goes to a temporary file next to the target, is flushed to
// disk, and is renamed over the target only when complete. A crash or an error never leaves a
// half-written file under the target name, and never destroys the file that was there.
//
// The temporary file is ".<name>.symoro-tmp.<host>.<pid>.<n>" (hidden, and recognisable): a
// process killed while writing leaves it behind, and the next atomic write of the same target
// removes it once its writer is gone (same host, kill(pid, 0) says no such process). A live
// writer's file, or another host's (a shared folder), is never touched.
#pragma once

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>

namespace symoro::io {

class AtomicFile {
 public:
  // Removes the target's stale temporary files, then opens a new one for writing; throws
  // DataError when it cannot.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Removes the temporary file if commit() was not called.
  ~AtomicFile();

  std::ostream& stream() { return out_; }
  // Flushes, fsyncs and renames over the target; throws DataError on any failure (the target
  // is then untouched), naming the system's reason ("no space left on device", ...).
  void commit();

  // The temporary file's name for `target` written by process `pid`, write number `n`.
  static std::filesystem::path temp_path(const std::filesystem::path& target, long pid, unsigned n);

 private:
  class Buffer;
  std::filesystem::path target_, temp_;
  std::unique_ptr<Buffer> buffer_;
  std::ostream out_;
  bool committed_ = false;
};

// Writes `content` to `target` atomically.
void write_file_atomically(const std::filesystem::path& target, const std::string& content);

}  // namespace symoro::io
