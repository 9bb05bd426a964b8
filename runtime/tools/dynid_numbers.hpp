// Numeric command-line options checked as they are parsed: a finite number in the option's
// range, with a short message. CLI11's own checks let nan through (--interval nan crashed the
// study) and print a double's whole range (300 digits) when they refuse.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace symoro::dynid::numbers {

// A number x with lo <= x <= hi (lo < x with lo_open); `integer`: also a whole number. `range`
// says the range in words for --help and the message, e.g. "> 0 and <= 60".
inline CLI::Validator checked(double lo, double hi, bool lo_open, bool integer, std::string range) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* s = text.c_str();
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(s, &end);
        if (end == s || *end != '\0') return fmt::format("'{}' is not a number", text);
        if (!std::isfinite(v)) return fmt::format("'{}': a finite number is needed ({})", text, range);
        if (integer && v != std::floor(v)) return fmt::format("'{}': a whole number is needed ({})", text, range);
        if ((lo_open ? v <= lo : v < lo) || v > hi)
          return fmt::format("{} is out of range: it must be {}", text, range);
        return "";
      },
      range);
}

inline CLI::Validator positive(double hi, const std::string& range) { return checked(0, hi, true, false, range); }
inline CLI::Validator non_negative(double hi, const std::string& range) { return checked(0, hi, false, false, range); }
// A seed (std::uint64_t): CLI11 read "-1" into it as 2^64 - 1, so a sign is refused.
inline CLI::Validator seed() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return text.find('-') == std::string::npos ? std::string()
                                                   : fmt::format("'{}': a seed is a whole number of at least 0", text);
      },
      "a whole number >= 0");
}
inline CLI::Validator count(double lo, double hi) {
  return checked(lo, hi, false, true, fmt::format("a whole number from {} to {}", lo, hi));
}
// Sampling intervals in ms: a run is named <trajectory>@<ms rounded>ms, so below 1 ms two
// intervals would share a name; past 10 s no log holds enough samples.
inline CLI::Validator interval_ms() { return checked(1, 10000, false, false, "from 1 to 10000 ms"); }

// The options of a command that reads logs as identification preprocesses them (predict,
// payload): --interval (ms), --torque-delay (ms) and --trial.
inline void add_log_options(CLI::App* cmd, double& interval, double& torque_delay, int& trial) {
  cmd->add_option("--interval", interval, "Sampling interval in ms, as in identification")
      ->check(interval_ms())
      ->capture_default_str();
  cmd->add_option("--torque-delay", torque_delay,
                  "ms the logged torque lags the links' (as dynid identify; default: the --params file's "
                  "torque_delay_ms, the delay the parameters were identified with)")
      ->check(checked(-1000, 1000, false, false, "from -1000 to 1000 ms"));
  cmd->add_option("--trial", trial, "Which trial of a dataset's runs")->check(count(1, 1e6))->capture_default_str();
}

}  // namespace symoro::dynid::numbers
