// The mapping's column selectors resolved against a table: header names, patterns with the
// joint number or name, or 1-based positions (import.hpp).
#include <algorithm>
#include <cctype>
#include <set>

#include <fmt/format.h>

#include "import_detail.hpp"
#include "symoro/error.hpp"

namespace symoro::io::detail {

namespace {

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = text.find(',', begin);
    std::string item = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    out.push_back(item);
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  return out;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 6 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// "3" or "2-8" (positions, 1-based); false when the item has another form.
bool position_item(const std::string& item, int& first, int& last) {
  const std::size_t dash = item.find('-');
  const std::string a = item.substr(0, dash), b = dash == std::string::npos ? a : item.substr(dash + 1);
  if (!all_digits(a) || !all_digits(b)) return false;
  first = std::stoi(a);
  last = std::stoi(b);
  return true;
}

// Where a selector error is: in the input file (at its header or first line), naming the
// mapping's key and origin so that either can be corrected.
struct Place {
  const TextTable& table;
  const ImportMapping& mapping;
  const std::string& key;
  const std::string& selector;
  int line() const { return table.has_header() ? table.header_line() : table.first_line(); }
  std::string origin() const {
    const int l = mapping_line(mapping, key);
    return l > 0 ? fmt::format("{}:{}", mapping.origin, l) : mapping.origin;
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw DataError(table.file(), line(), fmt::format("{}: '{}' ({}): {}", key, selector, origin(), message));
  }
};

std::string joint_list(const ImportTarget& target) {
  std::string out;
  for (const std::string& j : target.joints) out += (out.empty() ? "" : ", ") + j;
  return out;
}

std::string joints_note(const ImportTarget& target) {
  return fmt::format("the robot '{}' has {} joint{} ({})", target.robot, target.joints.size(),
                     target.joints.size() == 1 ? "" : "s", joint_list(target));
}

std::vector<int> by_position(const std::vector<std::string>& items, int count, const Place& at,
                             const ImportTarget& target) {
  std::vector<int> columns;
  for (const std::string& item : items) {
    int first = 0, last = 0;
    position_item(item, first, last);
    if (first < 1 || last < first) at.fail(fmt::format("'{}' is not a column range (1-based, first <= last)", item));
    for (int c = first; c <= last; ++c) {
      if (c > at.table.field_count())
        at.fail(fmt::format("column {} does not exist: the file has {} columns", c, at.table.field_count()));
      columns.push_back(c - 1);
    }
  }
  if (static_cast<int>(columns.size()) != count)
    at.fail(count == 1 ? fmt::format("selects {} columns, expected one", columns.size())
                       : fmt::format("selects {} columns but {}", columns.size(), joints_note(target)));
  return columns;
}

int header_column(const std::string& name, const Place& at) {
  const auto& header = at.table.header();
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) at.fail(fmt::format("no column '{}' in the header", name));
  const auto again = std::find(it + 1, header.end(), name);
  if (again != header.end())
    at.fail(fmt::format("column name '{}' appears twice (columns {} and {})", name, it - header.begin() + 1,
                        again - header.begin() + 1));
  return static_cast<int>(it - header.begin());
}

// "pos_*" (1-based) or "pos_%" (0-based): every column prefix<number>suffix, which must be
// exactly the joints' numbers.
std::vector<int> by_number_pattern(const std::string& pattern, std::size_t at_char, int count, const Place& at,
                                   const ImportTarget& target) {
  const int base = pattern[at_char] == '*' ? 1 : 0;
  const std::string prefix = pattern.substr(0, at_char), suffix = pattern.substr(at_char + 1);
  std::set<int> found;
  for (const std::string& name : at.table.header()) {
    if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (all_digits(digits) && (digits.size() == 1 || digits[0] != '0')) found.insert(std::stoi(digits));
  }
  const bool extra = !found.empty() && (*found.begin() < base || *found.rbegin() >= base + count);
  if (extra || static_cast<int>(found.size()) > count) {
    // Exactly the joints, numbered from the other end (ROS's joint_states exports count from 0).
    const int other = 1 - base;
    const bool other_base =
        static_cast<int>(found.size()) == count && *found.begin() == other && *found.rbegin() == other + count - 1;
    at.fail(fmt::format(
        "matches {} column{} numbered {}..{}, but {}{}", found.size(), found.size() == 1 ? "" : "s", *found.begin(),
        *found.rbegin(), joints_note(target),
        other_base ? fmt::format("; for numbers from {} write '{}{}{}'", other, prefix, other == 0 ? '%' : '*', suffix)
                   : std::string()));
  }
  std::vector<int> columns;
  for (int j = 0; j < count; ++j) {
    const std::string name = prefix + std::to_string(base + j) + suffix;
    if (!found.count(base + j))
      at.fail(fmt::format("no column '{}' for joint {}: the header has {} column{} of this pattern, but {}", name,
                          j + 1, found.size(), found.size() == 1 ? "" : "s", joints_note(target)));
    columns.push_back(header_column(name, at));
  }
  return columns;
}

std::vector<int> by_name(const std::vector<std::string>& items, int count, const Place& at,
                         const ImportTarget& target) {
  if (!at.table.has_header())
    throw DataError(at.table.file(), at.table.first_line(),
                    fmt::format("{}: '{}' ({}) selects columns by name, but the file has no header row (its first "
                                "row is numbers): select by position, e.g. 2-8",
                                at.key, at.selector, at.origin()));
  if (items.size() == 1) {
    const std::string& s = items.front();
    const std::size_t star = s.find_first_of("*%");
    const std::size_t brace = s.find("{name}");
    if (count > 1 && star != std::string::npos) return by_number_pattern(s, star, count, at, target);
    if (count > 1 && brace != std::string::npos) {
      std::vector<int> columns;
      for (const std::string& joint : target.joints)
        columns.push_back(header_column(s.substr(0, brace) + joint + s.substr(brace + 6), at));
      return columns;
    }
  }
  if (static_cast<int>(items.size()) != count)
    at.fail(count == 1 ? fmt::format("names {} columns, expected one", items.size())
                       : fmt::format("names {} columns but {} (a pattern: 'pos_*', 'pos_%' or '{{name}}_pos')",
                                     items.size(), joints_note(target)));
  std::vector<int> columns;
  for (const std::string& name : items) columns.push_back(header_column(name, at));
  return columns;
}

}  // namespace

int mapping_line(const ImportMapping& mapping, const std::string& key) {
  const auto it = mapping.lines.find(key);
  return it == mapping.lines.end() ? 0 : it->second;
}

std::vector<int> resolve_selector(const std::string& selector, const std::string& key, int count,
                                  const TextTable& table, const ImportMapping& mapping, const ImportTarget& target) {
  const Place at{table, mapping, key, selector};
  const std::vector<std::string> items = split_list(selector);
  int first = 0, last = 0;
  const bool positions =
      std::all_of(items.begin(), items.end(), [&](const std::string& i) { return position_item(i, first, last); });
  return positions ? by_position(items, count, at, target) : by_name(items, count, at, target);
}

}  // namespace symoro::io::detail
