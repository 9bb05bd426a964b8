// The entries of a .par file by name, with typed accessors that report precise errors: the check
// stage reads the description through it.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "symoro/grammar/ast.hpp"
#include "symoro/grammar/evaluate.hpp"

namespace symoro::codegen::load {

class ParReader {
 public:
  // `constants` (robot.yaml) give the geometric constants their values.
  ParReader(const grammar::ParFile& par, const std::map<std::string, double>& constants);

  // The entry `name`; an error on the file when it has none.
  const grammar::ParEntry& entry(const std::string& name) const;
  bool has(const std::string& name) const { return entries_.count(name) > 0; }

  // The entry `name`, which must be a list of `size` values.
  const std::vector<grammar::Expr>& list(const std::string& name, std::size_t size) const;

  // The value of an expression over the constants; an error at the expression otherwise.
  double value(const grammar::Expr& e) const;

  // The entry `name` as one whole number in [0, 10000].
  int integer(const std::string& name) const;

  const std::string& path() const { return par_.path; }

 private:
  const grammar::ParFile& par_;
  std::map<std::string, const grammar::ParEntry*> entries_;
  grammar::Bindings bindings_;
};

}  // namespace symoro::codegen::load
