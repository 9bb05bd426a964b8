#include "par_reader.hpp"

#include <cmath>
#include <stdexcept>

#include "stages.hpp"

namespace symoro::codegen::load {

ParReader::ParReader(const grammar::ParFile& par, const std::map<std::string, double>& constants) : par_(par) {
  for (const auto& e : par.entries) entries_[e.name] = &e;
  for (const auto& [k, v] : constants) bindings_[k] = v;
}

const grammar::ParEntry& ParReader::entry(const std::string& name) const {
  auto it = entries_.find(name);
  if (it == entries_.end()) throw InputError(par_.path, 0, 0, "missing entry '" + name + "'");
  return *it->second;
}

const std::vector<grammar::Expr>& ParReader::list(const std::string& name, std::size_t size) const {
  const auto& e = entry(name);
  if (!e.is_list || e.values.size() != size)
    fail_at(par_.path, e.at, "'" + name + "' must be a list of " + std::to_string(size) + " values");
  return e.values;
}

double ParReader::value(const grammar::Expr& e) const {
  try {
    return grammar::evaluate(e, bindings_);
  } catch (const std::runtime_error& err) {
    fail_at(par_.path, e.at,
            std::string(err.what()) + " (geometric constants take their values from robot.yaml 'constants')");
  }
}

int ParReader::integer(const std::string& name) const {
  const auto& e = entry(name);
  if (e.is_list || e.values.size() != 1) fail_at(par_.path, e.at, "'" + name + "' must be one number");
  const double v = value(e.values[0]);
  if (v != std::floor(v) || v < 0 || v > 10000) fail_at(par_.path, e.at, "'" + name + "' must be a whole number");
  return static_cast<int>(v);
}

}  // namespace symoro::codegen::load
