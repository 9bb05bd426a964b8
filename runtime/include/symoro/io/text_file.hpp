// A whole file as text (YAML, CSV, URDF read in one piece); writing is atomic_file.hpp's.
#pragma once

#include <filesystem>
#include <string>

namespace symoro::io {

// DataError when `path` exists and is no regular file (a folder, a device such as /dev/zero,
// a FIFO, a socket): readers read files only. Nothing when it does not exist (the opening says).
void check_regular_file(const std::filesystem::path& path);

// The file's bytes; DataError(path, 0, missing_message) when it cannot be opened or is no
// regular file.
std::string read_text_file(const std::filesystem::path& path,
                           const std::string& missing_message = "cannot read the file");

}  // namespace symoro::io
