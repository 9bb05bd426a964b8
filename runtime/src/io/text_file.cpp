#include "symoro/io/text_file.hpp"

#include <fstream>
#include <sstream>

#include "symoro/detail/regular_file.hpp"
#include "symoro/error.hpp"

namespace symoro::io {

void check_regular_file(const std::filesystem::path& path) {
  if (const std::string why = ::symoro::detail::not_a_regular_file(path); !why.empty())
    throw DataError(path.string(), 0, why);
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
