#include "symoro/io/number_text.hpp"

#include <charconv>
#include <system_error>

namespace symoro::io {

char* to_text(char* first, double value) {
  // Without a format argument, to_chars gives the shortest text that from_chars reads back
  // bit for bit (including the sign of -0).
  return std::to_chars(first, first + max_number_chars, value).ptr;
}

void append_number(std::string& out, double value) {
  char buffer[max_number_chars];
  out.append(buffer, to_text(buffer, value));
}

std::string number_text(double value) {
  std::string out;
  append_number(out, value);
  return out;
}

NumberParse parse_number(std::string_view text, double& value) {
  const char* const end = text.data() + text.size();
  double parsed = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), end, parsed);
  if (ptr != end || text.empty()) return NumberParse::not_a_number;
  if (ec == std::errc::result_out_of_range) return NumberParse::out_of_range;
  if (ec != std::errc()) return NumberParse::not_a_number;
  value = parsed;
  return NumberParse::ok;
}

}  // namespace symoro::io
