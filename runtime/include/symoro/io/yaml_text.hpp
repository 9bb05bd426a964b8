// YAML scalars for the files written as text (dataset.yaml, import.yaml, parameter files):
// strings double-quoted, numbers in their shortest round-trip form, so that they read back
// exactly.
#pragma once

#include <string>

namespace symoro::io {

// "text" with '"' and '\' escaped and control characters as \xNN.
std::string yaml_quoted(const std::string& text);

// Shortest text that reads back to the same double; .nan, .inf and -.inf for the others.
std::string yaml_number(double v);

}  // namespace symoro::io
