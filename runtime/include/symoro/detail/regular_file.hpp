// Readers read files only: what the runtime's readers (io/text_file.hpp) and the compiler's
// (robot.yaml, URDF) say of a path that is something else. Header-only, so that the compiler
// links no runtime library.
#pragma once

#include <filesystem>
#include <string>

namespace symoro::detail {

// Why `path` is no file to read, or "" when it is a regular file or does not exist (the
// opening says so then). /dev/zero grew a reader to 23 GB; a FIFO without a writer blocked it.
inline std::string not_a_regular_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st) || std::filesystem::is_regular_file(st)) return "";
  return std::filesystem::is_directory(st) ? "a folder, where a file is expected"
                                           : "not a regular file (a device, a FIFO or a socket): only files are read";
}

}  // namespace symoro::detail
