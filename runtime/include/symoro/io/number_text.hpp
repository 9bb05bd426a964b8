// Numbers as text for data files: the shortest decimal that reads back as exactly the same
// double, and a strict parser (the whole text must be one number) that never goes through a
// stream or the C locale, so a log reads the same everywhere and at full speed.
#pragma once

#include <string>
#include <string_view>

namespace symoro::io {

// Room to_text may use: the longest shortest form ("-2.2250738585072014e-308") is 24 chars.
constexpr int max_number_chars = 32;

// Writes the shortest round-trip form of `value` at `first` (e.g. "0.1", "-0", "1e-300",
// "nan", "inf") and returns one past its end. `first` must have max_number_chars of room.
char* to_text(char* first, double value);

// Appends the shortest round-trip form of `value`.
void append_number(std::string& out, double value);
std::string number_text(double value);

enum class NumberParse { ok, not_a_number, out_of_range };

// Parses all of `text` as a decimal number in std::from_chars syntax: no spaces, no leading
// '+'. "nan" and "inf" parse (callers that need finite numbers check). A value outside the
// range of double (1e999) is out_of_range; `value` is set only when the result is ok.
NumberParse parse_number(std::string_view text, double& value);

}  // namespace symoro::io
