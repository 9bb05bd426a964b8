// libFuzzer entry point for the grammar: any input must either parse or throw ParseError with a
// real position. Another exception, a crash, a sanitizer report, a hang or a parsed tree with an
// unset position is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "symoro/grammar/parser.hpp"

using namespace symoro::grammar;

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void check(const Position& at) { check(at.line >= 1 && at.column >= 1); }

void check(const Expr& e, int depth = 0) {
  check(e.at);
  check(depth <= 1024);
  for (const Expr& arg : e.args) check(arg, depth + 1);
}

void check(const Table& table) {
  check(table.at);
  for (const Table::Row& row : table.rows) {
    check(row.at);
    check(row.cells.size() == table.columns.size());
    for (const Expr& cell : row.cells) check(cell);
  }
}

void check(const ParseError& e) { check(e.line() >= 1 && e.column() >= 1 && !e.message().empty()); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const ModelFile file = parse_model_file(text, "fuzz.txt");
    for (const Table& t : file.tables) check(t);
    for (const Table& t : file.grouped_tables) check(t);
    check(file.equations_at);
    for (const Equation& eq : file.equations) {
      check(eq.at);
      check(eq.value);
    }
  } catch (const ParseError& e) {
    check(e);
  }
  try {
    const ParFile file = parse_par_file(text, "fuzz.par");
    for (const ParEntry& entry : file.entries) {
      check(entry.at);
      check(entry.is_list || entry.values.size() == 1);
      for (const Expr& v : entry.values) check(v);
    }
  } catch (const ParseError& e) {
    check(e);
  }
  try {
    check(parse_expression(text, "fuzz"));
  } catch (const ParseError& e) {
    check(e);
  }
  return 0;
}
