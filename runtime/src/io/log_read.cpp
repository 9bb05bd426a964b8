// Reading a log: the whole CSV in memory, numbers parsed in place with std::from_chars into
// matrices sized from the line count, every problem reported with its 1-based line.
#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "cell_text.hpp"
#include "log_columns.hpp"
#include "log_sidecar.hpp"
#include "symoro/error.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/text_file.hpp"

namespace symoro::io {

using detail::Column;
using detail::Group;

namespace {

std::string read_bytes(const std::filesystem::path& path) {
  check_regular_file(path);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw DataError(path.string(), 0, fmt::format("cannot open the log ({})", std::strerror(errno)));
  std::string bytes;
  char block[1 << 16];
  std::size_t got = 0;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec) bytes.reserve(size);
  while ((got = std::fread(block, 1, sizeof block, f)) > 0) bytes.append(block, got);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) throw DataError(path.string(), 0, "cannot read the log");
  return bytes;
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

// Lines of a buffer, without their "\n" or "\r\n"; a final newline does not start a line.
class Lines {
 public:
  Lines(const char* begin, const char* end) : p_(begin), end_(end) {}
  bool next(std::string_view& line) {
    if (p_ == end_) return false;
    const char* newline = static_cast<const char*>(std::memchr(p_, '\n', end_ - p_));
    const char* line_end = newline ? newline : end_;
    const char* content_end = line_end > p_ && line_end[-1] == '\r' ? line_end - 1 : line_end;
    line = std::string_view(p_, content_end - p_);
    p_ = newline ? newline + 1 : end_;
    ++number_;
    return true;
  }
  int number() const { return number_; }  // 1-based number of the last line returned

 private:
  const char* p_;
  const char* end_;
  int number_ = 0;
};

// "'q7'" or "'q7', 'qd7'".
std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "'" : ", '") + name + "'";
  return out;
}

// The header row: which group and joint each CSV column holds, checked against the sidecar.
std::vector<Column> parse_header(std::string_view header, const detail::Sidecar& sidecar, const std::string& file) {
  const int joints = static_cast<int>(sidecar.meta.joints.size());
  const bool reference = sidecar.meta.source == detail::reference_source;
  std::vector<Column> columns;
  std::map<std::pair<Group, int>, std::size_t> seen;  // column -> 1-based position in the header
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = header.find(',', start);
    const std::string_view raw =
        header.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    const std::string_view raw_name = trim(raw);
    const std::string name = detail::shown_text(raw_name, 80);  // as messages quote it
    const std::size_t position = columns.size() + 1;
    if (name.empty()) throw DataError(file, 1, fmt::format("column {} of the header has no name", position));
    const auto column = detail::parse_column_name(raw_name);
    if (!column)
      throw DataError(file, 1,
                      fmt::format("unknown column '{}' (a log has time, q<j>, qd<j>, tau<j>, q_ref<j>, "
                                  "qd_ref<j> and qdd_ref<j> for joints j = 1..{})",
                                  name, joints));
    if (column->joint >= joints)
      throw DataError(file, 1,
                      fmt::format("unknown column '{}': joint {} does not exist, the sidecar lists {} joints", name,
                                  column->joint + 1, joints));
    if (reference && std::find(detail::measured_groups.begin(), detail::measured_groups.end(), column->group) !=
                         detail::measured_groups.end())
      throw DataError(file, 1,
                      fmt::format("unknown column '{}' in a reference file (source: reference), which holds "
                                  "time, q_ref, qd_ref and qdd_ref only",
                                  name));
    const auto [previous, inserted] = seen.emplace(std::pair{column->group, column->joint}, position);
    if (!inserted)
      throw DataError(file, 1,
                      fmt::format("duplicate column '{}' (columns {} and {})", name, previous->second, position));
    columns.push_back(*column);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }

  const auto missing_in = [&](const auto& groups) {
    std::vector<std::string> missing;
    for (Group g : groups)
      for (int j = 0; j < joints; ++j)
        if (!seen.count({g, j})) missing.push_back(detail::column_name({g, j}));
    return missing;
  };
  const std::string joint_count_note = fmt::format(" (the sidecar lists {} joints)", joints);
  if (!seen.count({Group::time, 0})) throw DataError(file, 1, "missing column 'time'");
  if (!reference) {
    const std::vector<std::string> missing = missing_in(detail::measured_groups);
    if (!missing.empty())
      throw DataError(
          file, 1,
          fmt::format("missing column{} {}{}", missing.size() > 1 ? "s" : "", quoted_list(missing), joint_count_note));
  }
  const std::vector<std::string> missing_references = missing_in(detail::reference_groups);
  const bool any_reference = missing_references.size() < 3 * static_cast<std::size_t>(joints);
  if (reference && !missing_references.empty())
    throw DataError(file, 1,
                    fmt::format("missing column{} {} in a reference file{}", missing_references.size() > 1 ? "s" : "",
                                quoted_list(missing_references), joint_count_note));
  if (any_reference && !missing_references.empty())
    throw DataError(
        file, 1,
        fmt::format("partial reference group: missing column{} {} (q_ref, qd_ref and qdd_ref "
                    "come together, for every joint){}",
                    missing_references.size() > 1 ? "s" : "", quoted_list(missing_references), joint_count_note));
  return columns;
}

// Parses the data rows into the columns' destinations, one row per line, checking each field.
class RowParser {
 public:
  RowParser(const std::string& file, const std::vector<Column>& columns, std::vector<double*> destinations)
      : file_(file), columns_(columns), destinations_(std::move(destinations)) {}

  // Parses row `row` (0-based) from `line`, which is line `line_number` of the file.
  void parse(std::string_view line, Eigen::Index row, int line_number) {
    line_number_ = line_number;
    if (trim(line).empty()) throw DataError(file_, line_number, "blank line (every line after the header is a sample)");
    const char* p = line.data();
    const char* const end = line.data() + line.size();
    const std::size_t count = columns_.size();
    for (std::size_t c = 0; c < count; ++c) {
      if (c > 0) {
        if (p == end) fail_field_count(c);
        ++p;  // the comma
      }
      double value;
      const auto [ptr, ec] = std::from_chars(p, end, value);
      if (ec == std::errc() && (ptr == end || *ptr == ',') && std::isfinite(value)) {
        p = ptr;
      } else {
        p = parse_awkward_field(p, end, c, value);
      }
      destinations_[c][row] = value;
    }
    if (p != end) fail_field_count(count + static_cast<std::size_t>(std::count(p, end, ',')));
  }

 private:
  // The slow path: spaces around the number, or an error to describe. Returns the field's end.
  const char* parse_awkward_field(const char* p, const char* end, std::size_t c, double& value) const {
    const char* comma = static_cast<const char*>(std::memchr(p, ',', end - p));
    const char* field_end = comma ? comma : end;
    const std::string_view text = trim(std::string_view(p, field_end - p));
    const std::string column = detail::column_name(columns_[c]);
    if (text.empty()) throw DataError(file_, line_number_, fmt::format("empty field in column '{}'", column));
    const std::string shown = detail::shown_text(text);
    switch (parse_number(text, value)) {
      case NumberParse::not_a_number:
        throw DataError(file_, line_number_, fmt::format("'{}' in column '{}' is not a number", shown, column));
      case NumberParse::out_of_range:
        throw DataError(file_, line_number_,
                        fmt::format("'{}' in column '{}' is out of the range of a double", shown, column));
      case NumberParse::ok:
        break;
    }
    if (!std::isfinite(value))
      throw DataError(file_, line_number_, fmt::format("column '{}' holds '{}', not a finite number", column, shown));
    return field_end;
  }

  [[noreturn]] void fail_field_count(std::size_t fields) const {
    throw DataError(
        file_, line_number_,
        fmt::format("row has {} field{}, the header has {}", fields, fields == 1 ? "" : "s", columns_.size()));
  }

  const std::string& file_;
  const std::vector<Column>& columns_;
  std::vector<double*> destinations_;
  int line_number_ = 0;
};

}  // namespace

LogMetadata read_log_metadata(const std::filesystem::path& csv) {
  return detail::read_sidecar(metadata_path(csv)).meta;
}

Log read_log(const std::filesystem::path& csv) {
  const std::string file = csv.string();
  const std::string bytes = read_bytes(csv);
  const detail::Sidecar sidecar = detail::read_sidecar(metadata_path(csv));

  std::string_view text = bytes;
  constexpr std::string_view byte_order_mark = "\xEF\xBB\xBF";
  if (text.substr(0, byte_order_mark.size()) == byte_order_mark) text.remove_prefix(byte_order_mark.size());
  Lines lines(text.data(), text.data() + text.size());
  std::string_view header;
  if (!lines.next(header) || trim(header).empty()) throw DataError(file, 1, "no header row");
  // The writers end every line with a newline; a last line without one was cut while it was
  // written (a killed process, a full disk), and its last number may still parse ("-0" of
  // "-0.737"), so the file is refused rather than read short of a digit.
  if (text.back() != '\n')
    throw DataError(file, static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 1,
                    "the last line has no newline at its end: the file was cut while it was written "
                    "(its last number may be incomplete)");
  const std::vector<Column> columns = parse_header(header, sidecar, file);

  Log log;
  log.meta = sidecar.meta;
  const bool reference = log.meta.source == detail::reference_source;
  const bool has_references =
      reference || std::any_of(columns.begin(), columns.end(), [](const Column& c) { return c.group == Group::q_ref; });
  std::vector<Group> groups{Group::time};
  if (!reference) groups.insert(groups.end(), detail::measured_groups.begin(), detail::measured_groups.end());
  if (has_references) groups.insert(groups.end(), detail::reference_groups.begin(), detail::reference_groups.end());
  detail::check_units_cover(sidecar, groups);

  // Every line after the header is a sample (a blank one is an error), so the line count sizes
  // the matrices exactly.
  const Eigen::Index rows = std::count(text.begin(), text.end(), '\n') - 1;
  if (rows == 0)
    throw DataError(file, 2,
                    sidecar.meta.notes.empty()
                        ? std::string("no data rows after the header")
                        : "no data rows after the header; the sidecar's notes: " + sidecar.meta.notes);
  const Eigen::Index joints = static_cast<Eigen::Index>(log.meta.joints.size());
  log.time.resize(rows);
  for (Group g : groups)
    if (g != Group::time) detail::group_matrix(log, g).resize(rows, joints);
  for (Group g : {Group::q, Group::qd, Group::tau, Group::q_ref, Group::qd_ref, Group::qdd_ref})
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) detail::group_matrix(log, g).resize(rows, 0);
  std::vector<double*> destinations;
  for (const Column& c : columns)
    destinations.push_back(c.group == Group::time ? log.time.data()
                                                  : detail::group_matrix(log, c.group).col(c.joint).data());

  RowParser parser(file, columns, std::move(destinations));
  std::string_view line;
  for (Eigen::Index row = 0; lines.next(line); ++row) {
    parser.parse(line, row, lines.number());
    if (row > 0 && !(log.time[row] > log.time[row - 1]))
      throw DataError(file, lines.number(),
                      fmt::format("time does not increase strictly: {} s here, {} s on line {} before it",
                                  number_text(log.time[row]), number_text(log.time[row - 1]), lines.number() - 1));
  }

  if (rows != sidecar.samples)
    throw DataError(
        file, rows > sidecar.samples ? static_cast<int>(sidecar.samples) + 2 : 0,
        fmt::format("the CSV has {} samples but its sidecar ({}:{}) says samples: {}{}", rows, sidecar.file,
                    sidecar.samples_line, sidecar.samples, rows < sidecar.samples ? " (truncated CSV?)" : ""));
  return log;
}

}  // namespace symoro::io
