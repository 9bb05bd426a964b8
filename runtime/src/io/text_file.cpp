#include "symoro/io/text_file.hpp"

#include <fstream>
#include <sstream>

#include "symoro/error.hpp"

namespace symoro::io {

std::string read_text_file(const std::filesystem::path& path, const std::string& missing_message) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DataError(path.string(), 0, missing_message);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

}  // namespace symoro::io
