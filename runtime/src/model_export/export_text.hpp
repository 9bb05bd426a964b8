// Internal to model_export: the text helpers and description lookups the URDF and MJCF writers
// share.
#pragma once

#include <string>

#include "symoro/io/number_text.hpp"
#include "symoro/model_export/urdf_export.hpp"

namespace symoro::model_export::detail {

inline std::string num(double v) { return io::number_text(v == 0 ? 0.0 : v); }  // no "-0"

// XML attribute and comment text: the names come from robot.yaml.
inline std::string xml_escaped(const std::string& t) {
  std::string out;
  for (char c : t) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}
inline std::string comment_text(const std::string& t) {  // "--" may not appear in an XML comment
  std::string out = t;
  for (std::size_t p; (p = out.find("--")) != std::string::npos;) out.replace(p, 2, "- -");
  return out;
}

// std::invalid_argument on inconsistent sizes, antecedents or joint counts (urdf_export.cpp).
void check_description(const UrdfDescription& d);

// The joint (index into d.joints) of a movable frame, -1 for a fixed one.
inline int joint_of_frame(const UrdfDescription& d, int frame) {
  int k = -1;
  for (int f = 1; f <= frame; ++f)
    if (d.frames[static_cast<std::size_t>(f - 1)].sigma != 2) ++k;
  return d.frames[static_cast<std::size_t>(frame - 1)].sigma == 2 ? -1 : k;
}

// The value of a frame's parameter of `family` (IA, FV, FS); `found` says whether the model has it.
inline double frame_value(const UrdfDescription& d, const char* family, int frame, bool& found) {
  found = false;
  for (std::size_t k = 0; k < d.names.size(); ++k)
    if (d.names[k].joint == frame && std::string(d.names[k].family) == family) {
      found = true;
      return d.s(static_cast<Eigen::Index>(k));
    }
  return 0.0;
}

}  // namespace symoro::model_export::detail
