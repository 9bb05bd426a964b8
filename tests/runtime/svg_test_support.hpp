// Reading the project's SVG figures back in tests: axis tick labels and the panels of a figure.
#pragma once

#include <regex>
#include <string>
#include <vector>

namespace symoro::test {

inline std::vector<double> tick_values(const std::string& svg, const std::string& cls) {
  std::vector<double> v;
  const std::regex re("<text class=\"" + cls + "\"[^>]*>([^<]*)</text>");
  for (std::sregex_iterator it(svg.begin(), svg.end(), re), end; it != end; ++it) v.push_back(std::stod((*it)[1]));
  return v;
}

inline std::vector<std::string> panels(const std::string& svg) {
  std::vector<std::string> out;
  const std::string open = "<g class=\"panel\">";
  for (auto pos = svg.find(open); pos != std::string::npos;) {
    const auto next = svg.find(open, pos + 1);
    out.push_back(svg.substr(pos, next == std::string::npos ? std::string::npos : next - pos));
    pos = next;
  }
  return out;
}

}  // namespace symoro::test
