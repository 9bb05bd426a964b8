#include "symoro/report/markdown_table.hpp"

#include <algorithm>
#include <cctype>

namespace symoro::markdown {

namespace {

// A cell that reads as a number (or stands for a missing one).
bool numeric_cell(const std::string& c) {
  if (c.empty() || c == "--" || c == "n/a") return true;
  std::size_t i = c[0] == '-' || c[0] == '+' ? 1 : 0;
  return i < c.size() && (std::isdigit(static_cast<unsigned char>(c[i])) || c[i] == '.');
}

}  // namespace

std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n' || c == '\r')
      out += ' ';
    else
      out += c;
  }
  return out;
}

Table::Table(std::vector<std::string> header, Align align) : header_(std::move(header)), align_(align) {}

void Table::row(std::vector<std::string> cells) {
  cells.resize(header_.size());
  rows_.push_back(std::move(cells));
}

std::string Table::str() const {
  auto line = [](const std::vector<std::string>& cells) {
    std::string s = "|";
    for (const auto& c : cells) s += " " + cell(c) + " |";
    return s + "\n";
  };
  std::string out = line(header_) + "|";
  for (std::size_t i = 0; i < header_.size(); ++i) {
    const bool right =
        i > 0 && (align_ == Align::first_left ||
                  std::all_of(rows_.begin(), rows_.end(), [&](const auto& r) { return numeric_cell(r[i]); }));
    out += right ? "---:|" : ":---|";
  }
  out += "\n";
  for (const auto& r : rows_) out += line(r);
  return out;
}

}  // namespace symoro::markdown
