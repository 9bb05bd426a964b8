#include "symoro/io/text_file.hpp"

#include <fstream>
#include <sstream>

#include "symoro/error.hpp"

namespace symoro::io {

void check_regular_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  // /dev/zero grew a reader to 23 GB, a FIFO without a writer blocked it for ever.
  if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    throw DataError(path.string(), 0,
                    std::filesystem::is_directory(st) ? "a folder, where a file is expected"
                                                      : "not a regular file (a device, a FIFO or a socket): only files are read");
}

std::string read_text_file(const std::filesystem::path& path, const std::string& missing_message) {
  check_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DataError(path.string(), 0, missing_message);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

}  // namespace symoro::io
