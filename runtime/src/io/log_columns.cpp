#include "log_columns.hpp"

#include <algorithm>
#include <stdexcept>

namespace symoro::io::detail {

namespace {
struct GroupText {
  std::string_view name, unit;
};
constexpr std::array<GroupText, group_count> group_text = {{{"time", "s"},
                                                            {"q", "rad"},
                                                            {"qd", "rad/s"},
                                                            {"tau", "N*m"},
                                                            {"q_ref", "rad"},
                                                            {"qd_ref", "rad/s"},
                                                            {"qdd_ref", "rad/s^2"}}};

// "12" -> 12; nullopt for "", "0", "012", "1x" or absurdly long numbers.
std::optional<int> joint_number(std::string_view digits) {
  if (digits.empty() || digits.size() > 6 || digits[0] == '0') return std::nullopt;
  int n = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    n = n * 10 + (c - '0');
  }
  return n;
}
}  // namespace

std::string_view group_name(Group g) { return group_text[static_cast<int>(g)].name; }
std::string_view group_unit(Group g) { return group_text[static_cast<int>(g)].unit; }

std::optional<Group> group_named(std::string_view name) {
  for (Group g : all_groups)
    if (group_name(g) == name) return g;
  return std::nullopt;
}

std::optional<Column> parse_column_name(std::string_view name) {
  if (name == group_name(Group::time)) return Column{Group::time, 0};
  // Prefixes overlap ("q", "qd", "qdd_ref"): the name is a column only if what follows its
  // prefix is a joint number, and at most one prefix can leave digits behind.
  for (Group g : all_groups) {
    if (g == Group::time) continue;
    const std::string_view prefix = group_name(g);
    if (name.substr(0, prefix.size()) != prefix) continue;
    if (const auto n = joint_number(name.substr(prefix.size()))) return Column{g, *n - 1};
  }
  return std::nullopt;
}

std::string column_name(Column c) {
  std::string name(group_name(c.group));
  if (c.group != Group::time) name += std::to_string(c.joint + 1);
  return name;
}

const Eigen::MatrixXd& group_matrix(const Log& log, Group g) {
  switch (g) {
    case Group::q:
      return log.q;
    case Group::qd:
      return log.qd;
    case Group::tau:
      return log.tau;
    case Group::q_ref:
      return log.q_ref;
    case Group::qd_ref:
      return log.qd_ref;
    case Group::qdd_ref:
      return log.qdd_ref;
    case Group::time:
      break;
  }
  throw std::logic_error("group_matrix: time is a vector");
}

Eigen::MatrixXd& group_matrix(Log& log, Group g) {
  return const_cast<Eigen::MatrixXd&>(group_matrix(static_cast<const Log&>(log), g));
}

bool is_known_source(std::string_view source) {
  return std::find(known_sources.begin(), known_sources.end(), source) != known_sources.end();
}

std::vector<Group> groups_of(const Log& log) {
  std::vector<Group> groups{Group::time};
  if (log.meta.source != reference_source) groups.insert(groups.end(), measured_groups.begin(), measured_groups.end());
  if (log.meta.source == reference_source || log.has_references())
    groups.insert(groups.end(), reference_groups.begin(), reference_groups.end());
  return groups;
}

}  // namespace symoro::io::detail
