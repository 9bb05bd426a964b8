#include "symoro/io/yaml_keys.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "symoro/detail/yaml_checks.hpp"
#include "symoro/error.hpp"
#include "symoro/io/text_file.hpp"

namespace symoro::io {

namespace {
// A DataError at line (no column: the runtime's messages name file:line) for the shared checks.
struct Fail {
  const std::string& file;
  [[noreturn]] void operator()(int line, int column, const std::string& message) const {
    if (message.rfind("YAML syntax error", 0) == 0) throw DataError(file, line, column, message);
    throw DataError(file, line, message);
  }
};
}  // namespace

YAML::Node load_yaml_text(const std::string& raw, const std::string& file) {
  // A UTF-8 byte order mark (Windows editors write one) is no content; left in, it was reported as
  // an open quote on line 10.
  const bool bom = raw.compare(0, 3, "\xEF\xBB\xBF") == 0;
  const std::string text = bom ? raw.substr(3) : raw;
  ::symoro::detail::check_yaml_structure(text, Fail{file});
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    if (e.mark.is_null()) throw DataError(file, 0, "YAML syntax error: " + e.msg);
    throw DataError(file, e.mark.line + 1, e.mark.column + 1, "YAML syntax error: " + e.msg);
  }
  ::symoro::detail::check_quotes(root, text, Fail{file});
  return root;
}

YAML::Node load_yaml_file(const std::filesystem::path& path) {
  return load_yaml_text(read_text_file(path), path.string());
}

std::string nearest_name(const std::string& name, const std::vector<std::string>& known) {
  return ::symoro::detail::nearest_name(name, known);
}

void check_keys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& file,
                const std::string& where) {
  ::symoro::detail::check_keys(map, known, where, Fail{file});
}

}  // namespace symoro::io
