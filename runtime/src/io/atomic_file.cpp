#include "symoro/io/atomic_file.hpp"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

#include "symoro/error.hpp"

namespace symoro::io {

namespace {
std::atomic<unsigned> temp_counter{0};

// Flushes the file's data to disk so that the rename publishes complete content.
void sync_file(const std::filesystem::path& p) {
  const int fd = ::open(p.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  temp_ = target_;
  temp_ += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(temp_counter++);
  out_.open(temp_, std::ios::binary | std::ios::trunc);
  if (!out_)
    throw DataError(target_.string(), 0,
                    "cannot create a temporary file for writing (" + std::string(std::strerror(errno)) + ")");
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ec;
  std::filesystem::remove(temp_, ec);
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
    throw DataError(target_.string(), 0, "writing failed; the previous file is left as it was");
  }
  sync_file(temp_);
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) {
    std::filesystem::remove(temp_, ec);
    throw DataError(target_.string(), 0, "cannot rename the written file into place: " + ec.message());
  }
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& target, const std::string& content) {
  AtomicFile f(target);
  f.stream() << content;
  f.commit();
}

}  // namespace symoro::io
