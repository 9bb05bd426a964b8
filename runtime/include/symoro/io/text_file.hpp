// A whole file as text (YAML, CSV, URDF read in one piece); writing is atomic_file.hpp's.
#pragma once

#include <filesystem>
#include <string>

namespace symoro::io {

// The file's bytes; DataError(path, 0, missing_message) when it cannot be opened.
std::string read_text_file(const std::filesystem::path& path, const std::string& missing_message = "cannot read the file");

}  // namespace symoro::io
