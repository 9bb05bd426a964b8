// The column groups of a log (time, q, qd, tau, q_ref, qd_ref, qdd_ref): their names, SI
// units and where each lives in a Log. Shared by the log reader, writer and sidecar.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "symoro/io/log.hpp"

namespace symoro::io::detail {

enum class Group { time, q, qd, tau, q_ref, qd_ref, qdd_ref };
constexpr int group_count = 7;

constexpr std::array<Group, group_count> all_groups = {Group::time,  Group::q,      Group::qd,     Group::tau,
                                                       Group::q_ref, Group::qd_ref, Group::qdd_ref};
constexpr std::array<Group, 3> measured_groups = {Group::q, Group::qd, Group::tau};
constexpr std::array<Group, 3> reference_groups = {Group::q_ref, Group::qd_ref, Group::qdd_ref};

// "q_ref": the column prefix and the key in the sidecar's units map.
std::string_view group_name(Group g);
// The SI unit the log holds, as the sidecar writes it ("rad" stands for "m" on a prismatic
// joint, "N*m" for "N": the columns hold SI values either way).
std::string_view group_unit(Group g);
std::optional<Group> group_named(std::string_view name);

// A column: its group and 0-based joint (0 for time).
struct Column {
  Group group;
  int joint;
};

// "qd_ref3" -> {qd_ref, 2}; "time" -> {time, 0}. Joint numbers are 1-based in names, without
// leading zeros; the joint count is not checked here. nullopt when the name has no such form.
std::optional<Column> parse_column_name(std::string_view name);
std::string column_name(Column c);

// The matrix holding a joint group (not time) in a Log.
const Eigen::MatrixXd& group_matrix(const Log& log, Group g);
Eigen::MatrixXd& group_matrix(Log& log, Group g);

// The source of a reference file (time and the reference groups only).
constexpr std::string_view reference_source = "reference";
// Every source a log may have.
constexpr std::array<std::string_view, 3> known_sources = {"twin", "robot", "reference"};
bool is_known_source(std::string_view source);

// The groups a log holds, in the order the writer puts them.
std::vector<Group> groups_of(const Log& log);

}  // namespace symoro::io::detail
