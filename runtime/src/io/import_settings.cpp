// Import settings given by name (dynid import's options, symoro.import_logs' keywords) over a
// mapping, and a compiled model's joints as the importer's target.
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "symoro/io/import.hpp"

namespace symoro::io {

namespace {

template <class E>
void choose(const std::string& word, const char* setting, std::initializer_list<std::pair<const char*, E>> choices,
            E& out) {
  if (word.empty()) return;
  std::string list;
  for (const auto& [text, e] : choices) {
    if (word == text) {
      out = e;
      return;
    }
    list += (list.empty() ? "" : ", ") + std::string(text);
  }
  throw std::invalid_argument(fmt::format("{}: '{}' is not one of {}", setting, word, list));
}

}  // namespace

ImportTarget import_target(const std::string& robot, const std::vector<JointInfo>& joints) {
  ImportTarget t;
  t.robot = robot;
  for (const JointInfo& j : joints) {
    t.joints.emplace_back(j.name);
    t.prismatic.push_back(j.type == JointType::Prismatic);
    t.lower.push_back(j.lower);
    t.upper.push_back(j.upper);
    t.effort.push_back(j.effort);
  }
  return t;
}

void apply_settings(ImportMapping& m, const MappingSettings& s) {
  for (const auto& [text, target] : {std::pair{&s.time, &m.time},
                                     {&s.q, &m.q},
                                     {&s.qd, &m.qd},
                                     {&s.tau, &m.tau},
                                     {&s.q_ref, &m.q_ref},
                                     {&s.qd_ref, &m.qd_ref},
                                     {&s.qdd_ref, &m.qdd_ref}})
    if (!text->empty()) *target = *text;
  choose(s.time_unit, "time_unit",
         {{"s", TimeUnit::s}, {"ms", TimeUnit::ms}, {"us", TimeUnit::us}, {"ns", TimeUnit::ns}}, m.time_unit);
  choose(s.angle, "angle", {{"rad", AngleUnit::rad}, {"deg", AngleUnit::deg}}, m.angle_unit);
  choose(s.header, "header", {{"auto", HeaderRow::automatic}, {"yes", HeaderRow::present}, {"no", HeaderRow::absent}},
         m.header);
  choose(s.delimiter, "delimiter",
         {{"auto", Delimiter::automatic},
          {"comma", Delimiter::comma},
          {"semicolon", Delimiter::semicolon},
          {"whitespace", Delimiter::whitespace}},
         m.delimiter);
  if (s.torque_scale != 0) m.torque_scale = s.torque_scale;
}

}  // namespace symoro::io
