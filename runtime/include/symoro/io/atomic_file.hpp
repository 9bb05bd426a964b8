// Atomic file output: the content goes to a temporary file next to the target, is flushed to
// disk, and is renamed over the target only when complete. A crash or an error never leaves a
// half-written file under the target name, and never destroys the file that was there.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

namespace symoro::io {

class AtomicFile {
 public:
  // Opens "<target>.tmp.<pid>.<n>" for writing; throws DataError when it cannot.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Removes the temporary file if commit() was not called.
  ~AtomicFile();

  std::ostream& stream() { return out_; }
  // Flushes, fsyncs and renames over the target; throws DataError on any failure (the target
  // is then untouched).
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

// Writes `content` to `target` atomically.
void write_file_atomically(const std::filesystem::path& target, const std::string& content);

}  // namespace symoro::io
