// Reading an exported text table: the delimiter and the header row are recognised on the
// first line that is not a comment; the data rows are parsed only in the columns mapped.
#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "cell_text.hpp"
#include "import_detail.hpp"
#include "symoro/error.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/text_file.hpp"

namespace symoro::io::detail {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

// Lines without "\n" / "\r\n", numbered from 1.
class LineReader {
 public:
  LineReader(const std::string& text, std::size_t offset, int first_number)
      : text_(text), p_(offset), number_(first_number - 1) {}
  bool next(std::string_view& line) {
    if (p_ >= text_.size()) return false;
    const std::size_t newline = text_.find('\n', p_);
    const std::size_t end = newline == std::string::npos ? text_.size() : newline;
    line = std::string_view(text_).substr(p_, end - p_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    start_ = p_;
    p_ = newline == std::string::npos ? text_.size() : newline + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }
  std::size_t start() const { return start_; }  // offset of the last line returned

 private:
  const std::string& text_;
  std::size_t p_;
  int number_;
  std::size_t start_ = 0;
};

// Comment and blank lines carry no row.
bool is_content(std::string_view line) {
  const std::string_view t = trim(line);
  return !t.empty() && t.front() != '#';
}

// A number as exporters write it: from_chars syntax, plus a leading '+'.
NumberParse parse_field(std::string_view text, double& value) {
  if (text.size() > 1 && text.front() == '+' && text[1] != '-') text.remove_prefix(1);
  return parse_number(text, value);
}

bool is_number(std::string_view text) {
  double v;
  return parse_field(trim(text), v) == NumberParse::ok;
}

}  // namespace

TextTable::TextTable(const std::filesystem::path& file, Delimiter delimiter, HeaderRow header) : file_(file.string()) {
  bytes_ = read_text_file(file, "cannot open the file to import");
  std::size_t start = bytes_.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // UTF-8 byte order mark
  // Line ends of CR alone (classic Mac OS, some loggers): the whole file is one line without a
  // newline, and was reported as cut.
  if (bytes_.find('\n') == std::string::npos && bytes_.find('\r') != std::string::npos)
    throw DataError(file_, 1,
                    "the lines end in CR alone (no LF anywhere): convert the line ends to LF or CR LF (e.g. tr '\\r' "
                    "'\\n')");
  // A writer killed mid-row leaves a last line without its newline, whose last number may be
  // cut yet still parse ("-0" of "-0.737"): such a file is refused whole.
  if (!bytes_.empty() && bytes_.back() != '\n')
    throw DataError(file_, static_cast<int>(std::count(bytes_.begin(), bytes_.end(), '\n')) + 1,
                    "the last line has no newline at its end: the file may have been cut while it was written "
                    "(its last number may be incomplete); if the file is complete, end it with a newline");

  LineReader lines(bytes_, start, 1);
  std::string_view line;
  while (lines.next(line) && !is_content(line)) {
  }
  if (!is_content(line)) throw DataError(file_, 0, "no rows: the file is empty or holds comments only");
  first_line_ = lines.number();
  delimiter_ = delimiter;
  if (delimiter_ == Delimiter::automatic)
    delimiter_ = line.find(',') != std::string_view::npos   ? Delimiter::comma
                 : line.find(';') != std::string_view::npos ? Delimiter::semicolon
                                                            : Delimiter::whitespace;
  std::vector<std::string_view> fields;
  split(line, fields);
  fields_ = static_cast<int>(fields.size());
  bool header_row = header == HeaderRow::present;
  if (header == HeaderRow::automatic)
    for (std::string_view f : fields) header_row = header_row || !is_number(f);
  if (header_row) {
    header_line_ = first_line_;
    for (std::string_view f : fields) header_.emplace_back(f);
    data_offset_ = bytes_.find('\n', lines.start());
    data_offset_ = data_offset_ == std::string::npos ? bytes_.size() : data_offset_ + 1;
    data_first_number_ = first_line_ + 1;
  } else {
    data_offset_ = lines.start();
    data_first_number_ = first_line_;
  }
}

void TextTable::split(std::string_view line, std::vector<std::string_view>& fields) const {
  fields.clear();
  if (delimiter_ == Delimiter::whitespace) {
    std::size_t p = 0;
    while (true) {
      while (p < line.size() && is_blank(line[p])) ++p;
      if (p == line.size()) break;
      const std::size_t begin = p;
      while (p < line.size() && !is_blank(line[p])) ++p;
      fields.push_back(line.substr(begin, p - begin));
    }
    return;
  }
  const char d = delimiter_ == Delimiter::comma ? ',' : ';';
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = line.find(d, begin);
    fields.push_back(trim(line.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin)));
    if (end == std::string_view::npos) break;
    begin = end + 1;
  }
}

std::string TextTable::column_label(int column) const {
  if (has_header() && column < static_cast<int>(header_.size()))
    return fmt::format("'{}' (column {})", shown_text(header_[column], 80), column + 1);
  return fmt::format("column {}", column + 1);
}

void TextTable::read(const std::vector<int>& columns, std::vector<double>& values, std::vector<int>& lines) const {
  values.clear();
  lines.clear();
  LineReader reader(bytes_, data_offset_, data_first_number_);
  std::string_view line;
  std::vector<std::string_view> fields;
  while (reader.next(line)) {
    if (!is_content(line)) continue;
    split(line, fields);
    const int line_number = reader.number();
    if (static_cast<int>(fields.size()) != fields_)
      throw DataError(file_, line_number,
                      fmt::format("row has {} fields, the {} has {}", fields.size(),
                                  has_header() ? "header" : fmt::format("first row (line {})", first_line_), fields_));
    for (int c : columns) {
      const std::string_view text = fields[c];
      double v = 0;
      const NumberParse parsed = parse_field(text, v);
      if (text.empty()) throw DataError(file_, line_number, fmt::format("empty field in {}", column_label(c)));
      if (parsed != NumberParse::ok)
        throw DataError(file_, line_number,
                        fmt::format("'{}' in {} is not a number", shown_text(text), column_label(c)));
      if (!std::isfinite(v))
        throw DataError(file_, line_number,
                        fmt::format("{} holds '{}', not a finite number", column_label(c), shown_text(text)));
      values.push_back(v);
    }
    lines.push_back(line_number);
  }
  if (lines.empty()) throw DataError(file_, header_line_, "no data rows after the header");
}

}  // namespace symoro::io::detail
