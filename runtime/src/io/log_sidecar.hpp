// The metadata sidecar of a log ("<name>.meta.yaml"): its text, and reading it with the line
// of every problem. The CSV's own checks (columns, rows) live in the log reader.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "log_columns.hpp"
#include "symoro/io/log.hpp"

namespace symoro::io::detail {

// The format line every sidecar starts with; the reader refuses other versions.
constexpr std::string_view log_format = "symoro-log 1";

struct Sidecar {
  std::string file;                 // the sidecar's path, for messages
  LogMetadata meta;                 // checked: known source, robot and joint names non-empty, joints unique
  long long samples = 0;            // the CSV's row count when it was written
  int samples_line = 0;             // 1-based line of "samples:" in the sidecar
  std::map<Group, int> unit_lines;  // groups the units map names (each with the SI unit), and where
  int units_line = 0;
};

// Reads and checks the sidecar at `yaml`; throws DataError(yaml, line, ...) when it is missing,
// is not valid YAML, or has a missing, unknown, repeated or ill-formed key.
Sidecar read_sidecar(const std::filesystem::path& yaml);

// Throws DataError naming the sidecar's units map when it lacks one of `groups`.
void check_units_cover(const Sidecar& sidecar, const std::vector<Group>& groups);

// The sidecar text of a log that validate_log accepted; `file` names the sidecar in errors.
std::string sidecar_text(const Log& log, const std::string& file);

}  // namespace symoro::io::detail
