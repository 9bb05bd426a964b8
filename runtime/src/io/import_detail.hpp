// The importer's stages (import.hpp): reading a delimited text table, and resolving the
// mapping's column selectors against it.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "symoro/io/import.hpp"

namespace symoro::io::detail {

// A delimited text file: comment ('#') and blank lines skipped, the header row (if any) split
// into names, the data rows left as text until read() parses the columns asked for.
class TextTable {
 public:
  TextTable(const std::filesystem::path& file, Delimiter delimiter, HeaderRow header);
  const std::string& file() const { return file_; }
  bool has_header() const { return header_line_ > 0; }
  const std::vector<std::string>& header() const { return header_; }
  int header_line() const { return header_line_; }
  int first_line() const { return first_line_; }  // the first non-comment line
  int field_count() const { return fields_; }     // of the header, or of the first data row
  // The display name of a 0-based column: "'pos_1' (column 3)" or "column 3".
  std::string column_label(int column) const;
  // Parses `columns` (0-based) of every data row: values row-major (rows x columns.size()),
  // and each row's 1-based line. DataError(file, line) on a wrong field count or a field that
  // is not a finite number, naming its column.
  void read(const std::vector<int>& columns, std::vector<double>& values, std::vector<int>& lines) const;

 private:
  void split(std::string_view line, std::vector<std::string_view>& fields) const;
  std::string file_;
  std::string bytes_;
  Delimiter delimiter_ = Delimiter::comma;
  std::vector<std::string> header_;
  int header_line_ = 0, first_line_ = 0, fields_ = 0;
  std::size_t data_offset_ = 0;  // where the data rows start in bytes_
  int data_first_number_ = 0;    // line number of the line at data_offset_
};

// The 0-based columns of one selector (`key`: "time", "q", ...): `count` columns (1 for time,
// the joint count otherwise). Errors in the selector's form name the mapping's origin and the
// key's line; columns missing from the file, or a pattern matching another number of columns
// than joints, name the file's header line.
std::vector<int> resolve_selector(const std::string& selector, const std::string& key, int count,
                                  const TextTable& table, const ImportMapping& mapping, const ImportTarget& target);

// The line of `key` in the mapping (0 on the command line).
int mapping_line(const ImportMapping& mapping, const std::string& key);

// A time unit's name ("s", "ms", ...) and the exact factor a value in it is divided by to give
// seconds (dividing by an exactly representable integer rounds once: "1500" ms is exactly 1.5 s).
const char* time_unit_name(TimeUnit u);
double time_divisor(TimeUnit u);

// One line for the import's remarks: how the measured velocity agrees with the stamps
// (velocity_agreement), the joints off by more than 2 % named.
std::string velocity_remark(const Log& log);

}  // namespace symoro::io::detail
