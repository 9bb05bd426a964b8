// An exclusive lock on an output folder (flock on <folder>/.lock), so that two processes never
// write one study at the same time (the last writer used to win, silently). The lock file holds
// the holder's pid and command for the refusal's message; the kernel drops the lock when the
// holder exits, however it exits, so a killed run leaves no stale lock behind.
#pragma once

#include <filesystem>
#include <string>

namespace symoro::io {

class FolderLock {
 public:
  // Creates the folder when needed and takes the lock; throws DataError naming the folder and the
  // holder's pid when another process has it. `name`: the lock file in the folder (".lock"; one
  // file's own lock, e.g. ".arm.urdf.lock", lets other files of the folder be written meanwhile);
  // `remove_when_done`: the lock file goes when the lock is released (a user's folder keeps no
  // trace of it).
  FolderLock(const std::filesystem::path& folder, const std::string& what, const std::string& name = ".lock",
             bool remove_when_done = false);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  std::filesystem::path file_;
  bool remove_ = false;
  int fd_ = -1;
};

}  // namespace symoro::io
