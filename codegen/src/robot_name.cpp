#include "symoro/codegen/robot_name.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <string_view>

namespace symoro::codegen {

namespace {

// C++20's keywords and alternative tokens.
constexpr std::array<std::string_view, 96> kKeywords = {
    "alignas",     "alignof",   "and",        "and_eq",    "asm",      "auto",         "bitand",
    "bitor",       "bool",      "break",      "case",      "catch",    "char",         "char8_t",
    "char16_t",    "char32_t",  "class",      "compl",     "concept",  "const",        "consteval",
    "constexpr",   "constinit", "const_cast", "continue",  "co_await", "co_return",    "co_yield",
    "decltype",    "default",   "delete",     "do",        "double",   "dynamic_cast", "else",
    "enum",        "explicit",  "export",     "extern",    "false",    "float",        "for",
    "friend",      "goto",      "if",         "inline",    "int",      "long",         "mutable",
    "namespace",   "new",       "noexcept",   "not",       "not_eq",   "nullptr",      "operator",
    "or",          "or_eq",     "private",    "protected", "public",   "register",     "reinterpret_cast",
    "requires",    "return",    "short",      "signed",    "sizeof",   "static",       "static_assert",
    "static_cast", "struct",    "switch",     "template",  "this",     "thread_local", "throw",
    "true",        "try",       "typedef",    "typeid",    "typename", "union",        "unsigned",
    "using",       "virtual",   "void",       "volatile",  "wchar_t",  "while",        "xor",
    "xor_eq",      "final",     "override",   "import",    "module"};

// Namespaces the generated code and the robot library name from inside symoro::.
constexpr std::array<std::string_view, 6> kTaken = {"std", "Eigen", "ceres", "symoro", "detail", "grammar"};

}  // namespace

std::string robot_name_problem(const std::string& name) {
  const std::string quoted = "the robot's name '" + name + "'";
  if (name.empty()) return "the robot's name is empty";
  const bool identifier = (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') &&
                          std::all_of(name.begin(), name.end(),
                                      [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
  if (!identifier)
    return quoted + " is no C++ identifier (letters, digits and _; not a digit first); it names the robot's namespace";
  if (std::find(kKeywords.begin(), kKeywords.end(), name) != kKeywords.end())
    return quoted + " is a C++ keyword; it names the robot's namespace: choose another";
  if (std::find(kTaken.begin(), kTaken.end(), name) != kTaken.end())
    return quoted + " would hide the namespace " + name + " in the generated code: choose another";
  if (name.find("__") != std::string::npos ||
      (name[0] == '_' && name.size() > 1 && std::isupper(static_cast<unsigned char>(name[1]))))
    return quoted + " is reserved in C++ (a double underscore, or _ and a capital first): choose another";
  return "";
}

}  // namespace symoro::codegen
