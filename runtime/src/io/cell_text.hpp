// A cell's text as an error message quotes it: control bytes escaped (a NUL as \0, others as
// \xNN), so that a message never stops at a NUL nor breaks a terminal, and cut after `limit`
// bytes with "..." (a runaway field does not flood the message).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace symoro::io::detail {

inline std::string shown_text(std::string_view text, std::size_t limit = 40) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < limit; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == 0) {
      out += "\\0";
    } else if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (text.size() > limit) out += "...";
  return out;
}

}  // namespace symoro::io::detail
