// A Markdown table, for the study's and the diagnosis's reports: cells made table-safe ('|'
// escaped, line breaks as spaces), one alignment rule per table.
#pragma once

#include <string>
#include <vector>

namespace symoro::markdown {

// '|' escaped, line breaks as spaces.
std::string cell(const std::string& text);

enum class Align {
  numbers_right,  // the first column and columns of text left, columns of numbers right
  first_left,     // the first column left, every other right
};

class Table {
 public:
  explicit Table(std::vector<std::string> header, Align align = Align::numbers_right);
  void row(std::vector<std::string> cells);  // padded or cut to the header's width
  std::string str() const;                   // header, alignment row, rows; ends with a newline

 private:
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  Align align_;
};

}  // namespace symoro::markdown
