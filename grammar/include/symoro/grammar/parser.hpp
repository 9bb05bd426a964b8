// Parsers for OpenSYMORO files. Every failure is a ParseError that names the file, the line,
// the column and what was expected; no input crashes or hangs them (see tests/fuzz).
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "symoro/grammar/ast.hpp"

namespace symoro::grammar {

class ParseError : public std::runtime_error {
 public:
  ParseError(std::string file, int line, int column, std::string message, std::string source_line);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  // What went wrong, without the location ("expected ';' after the expression").
  const std::string& message() const { return message_; }
  // what() is "file:line:column: error: message" followed by the offending line and a caret.

 private:
  std::string file_;
  int line_;
  int column_;
  std::string message_;
};

// Deepest nesting of parentheses, unary minus and powers accepted in one expression; deeper
// input is rejected with a ParseError rather than risking the stack.
inline constexpr int kMaxExpressionDepth = 256;

// `path` is used only in messages.
ModelFile parse_model_file(std::string_view text, const std::string& path);
ParFile parse_par_file(std::string_view text, const std::string& path);
// One expression, the whole text (used for robot.yaml values and tests).
Expr parse_expression(std::string_view text, const std::string& path);

// Reads the file and parses it; a missing or unreadable file is a ParseError at line 0.
ModelFile read_model_file(const std::string& path);
ParFile read_par_file(const std::string& path);

}  // namespace symoro::grammar
