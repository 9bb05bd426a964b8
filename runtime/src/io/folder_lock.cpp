#include "symoro/io/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "symoro/error.hpp"

namespace symoro::io {

FolderLock::FolderLock(const std::filesystem::path& folder, const std::string& what, const std::string& name,
                       bool remove_when_done)
    : file_(folder / name), remove_(remove_when_done) {
  std::filesystem::create_directories(folder);
  const std::filesystem::path& file = file_;
  int err = 0;
  for (;;) {
    fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw DataError(file.string(), 0, fmt::format("cannot open the folder's lock file: {}", std::strerror(errno)));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      err = errno;
      break;
    }
    // Held: unless a holder that removes its file when done removed this one just before (a
    // lock on a file no one else finds); then again, on the file the name now gives.
    struct stat held {
    }, named{};
    if (::fstat(fd_, &held) == 0 && ::stat(file.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
        held.st_dev == named.st_dev)
      break;
    ::close(fd_);
  }
  if (err != 0) {
    // The holder writes its pid just after it takes the lock: a refusal in between waits a little
    // for it (at most 0.2 s) so that the message can name it.
    char holder[256] = {};
    ssize_t n = 0;
    for (int attempt = 0; attempt < 40 && (n = ::pread(fd_, holder, sizeof holder - 1, 0)) <= 0; ++attempt)
      ::usleep(5000);
    std::string who = n > 0 ? std::string(holder, static_cast<std::size_t>(n)) : std::string("another process");
    while (!who.empty() && (who.back() == '\n' || who.back() == '\r')) who.pop_back();
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK)
      throw DataError(
          folder.string(), 0,
          fmt::format("in use by {} (lock {}): two runs would overwrite each other's results; wait for it or "
                      "choose another folder",
                      who, file.string()));
    throw DataError(file.string(), 0, fmt::format("cannot lock the folder: {}", std::strerror(err)));
  }
  // Who holds it, for the next one's message (the lock, not this text, is what excludes).
  const std::string me = fmt::format("pid {} ({})\n", ::getpid(), what);
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t w = ::pwrite(fd_, me.data(), me.size(), 0);
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) {
    [[maybe_unused]] const int t = ::ftruncate(fd_, 0);
    if (remove_) ::unlink(file_.c_str());  // while still held: a later one creates its own
    ::close(fd_);                          // releases the lock
  }
}

}  // namespace symoro::io
