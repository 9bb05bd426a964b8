// Abstract syntax of OpenSYMORO files: the model files (dim, ddm, inm, idm, ccg, fgm, jac,
// regp) and the robot description (.par). The parser (parser.hpp) produces these plain
// structures; the compiler (codegen/) and the reference interpreter (evaluate.hpp) read them.
#pragma once

#include <string>
#include <vector>

namespace symoro::grammar {

// Where something stands in its file: 1-based line and column.
struct Position {
  int line = 0;
  int column = 0;
};

// An expression: a number, a symbol, a unary minus, a binary operator or a function call.
struct Expr {
  enum class Kind { Number, Symbol, Negate, Add, Subtract, Multiply, Divide, Power, Call };
  Kind kind = Kind::Number;
  double number = 0.0;     // Kind::Number
  std::string name;        // Kind::Symbol: the symbol; Kind::Call: the function name
  std::vector<Expr> args;  // Negate: 1, binary operators: 2 (left, right), Call: the arguments
  Position at;             // first character of the expression
};

// `NAME = expression;`
struct Equation {
  std::string name;
  Expr value;
  Position at;  // the first character of NAME
};

// A titled table such as "Geometric parameters": a header row of column names and data rows of
// cells, one cell per column. Cells are expressions (`0`, `th1`, `-pi/2`, `-G3`).
struct Table {
  std::string title;
  Position at;  // the title line
  std::vector<std::string> columns;
  struct Row {
    std::vector<Expr> cells;
    Position at;
  };
  std::vector<Row> rows;
};

// A whole model file. `title` holds the free-text lines before the first table (for example
// "Jacobian matrix for frame 7"). `tables` come before `Equations:`; `equations` run up to the
// first `*=*`. regp.txt has a second part after that marker ("Grouped inertial parameters",
// more tables, `*=*`): its tables go to `grouped_tables`.
struct ModelFile {
  std::string path;
  std::vector<std::string> title;
  std::vector<Table> tables;
  Position equations_at;  // the `Equations:` line
  std::vector<Equation> equations;
  std::string grouped_title;  // "Grouped inertial parameters" when present, else empty
  std::vector<Table> grouped_tables;
};

// One `NAME = value` or `NAME = {v1,v2,...}` line of a .par file. `False`/`True` are symbols.
struct ParEntry {
  std::string name;
  bool is_list = false;
  std::vector<Expr> values;  // one value when !is_list
  Position at;
};

// A .par robot description: `(* comments *)` are skipped; the robot name comes from the
// `(* Robotname = 'x' *)` comment when present.
struct ParFile {
  std::string path;
  std::string robot_name;
  std::vector<ParEntry> entries;
};

}  // namespace symoro::grammar
