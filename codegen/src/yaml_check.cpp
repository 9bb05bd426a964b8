#include "yaml_check.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "symoro/codegen/robot_spec.hpp"
#include "symoro/detail/regular_file.hpp"
#include "symoro/detail/yaml_checks.hpp"

namespace symoro::codegen {

namespace {
struct Fail {
  const std::string& file;
  [[noreturn]] void operator()(int line, int column, const std::string& message) const {
    throw InputError(file, line, column, message);
  }
};
}  // namespace

YAML::Node load_yaml_file(const std::string& path) {
  if (const std::string why = ::symoro::detail::not_a_regular_file(path); !why.empty())
    throw InputError(path, 0, 0, why);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, 0, "cannot open file");
  std::ostringstream content;
  content << in.rdbuf();
  std::string text = content.str();
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);  // a UTF-8 byte order mark is no content
  ::symoro::detail::check_yaml_structure(text, Fail{path});
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(path, e.mark.line + 1, e.mark.column + 1, "YAML syntax error: " + e.msg);
  }
  ::symoro::detail::check_quotes(root, text, Fail{path});
  return root;
}

std::string nearest_name(const std::string& name, const std::vector<std::string>& known) {
  return ::symoro::detail::nearest_name(name, known);
}

void check_keys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& file,
                const std::string& where) {
  ::symoro::detail::check_keys(map, known, where, Fail{file});
}

}  // namespace symoro::codegen
