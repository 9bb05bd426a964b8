#include "symoro/io/yaml_numbers.hpp"

#include <cmath>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/number_text.hpp"

namespace symoro::io {

double yaml_number(const YAML::Node& n, const std::string& file, const std::string& what) {
  double v = 0;
  if (!n || !n.IsScalar() || parse_number(n.Scalar(), v) != NumberParse::ok || !std::isfinite(v))
    throw DataError(file, n ? n.Mark().line + 1 : 0, what + ": not a finite number");
  return v;
}

Eigen::VectorXd yaml_numbers(const YAML::Node& n, std::size_t count, const std::string& file, const std::string& what) {
  if (!n || !n.IsSequence() || n.size() != count)
    throw DataError(file, n ? n.Mark().line + 1 : 0, fmt::format("{}: a list of {} numbers", what, count));
  Eigen::VectorXd v(static_cast<Eigen::Index>(count));
  for (std::size_t i = 0; i < count; ++i) v(static_cast<Eigen::Index>(i)) = yaml_number(n[i], file, what);
  return v;
}

}  // namespace symoro::io
