#include "dynid_urdf_into.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>
#include <yaml-cpp/yaml.h>

#include "dynid_common.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/mdh.hpp"
#include "symoro/urdf_geometry.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::dynid {

namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using urdf_geometry::pose;

struct Origin {
  std::string base_link;
  std::vector<std::string> joints;
  std::vector<std::vector<std::string>> links;
  std::map<std::string, double> locked;
  Isometry3d frame0 = Isometry3d::Identity();
};

Isometry3d xyz_rpy(const YAML::Node& n) {
  const auto xyz = n["xyz"].as<std::vector<double>>(), rpy = n["rpy"].as<std::vector<double>>();
  Isometry3d T = Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(rpy.at(2), Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.at(1), Vector3d::UnitY()) *
                Eigen::AngleAxisd(rpy.at(0), Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Vector3d(xyz.at(0), xyz.at(1), xyz.at(2));
  return T;
}

Origin read_origin(const std::string& robot_yaml) {
  Origin o;
  try {
    const YAML::Node u = io::load_yaml_file(robot_yaml)["urdf"];
    if (!u)
      throw UsageError(robot_yaml + " has no `urdf:` section: --into needs a robot symoroc model made from a URDF");
    o.base_link = u["base_link"].as<std::string>();
    o.joints = u["joints"].as<std::vector<std::string>>();
    o.links = u["links"].as<std::vector<std::vector<std::string>>>();
    if (u["locked"])
      for (const auto& kv : u["locked"]) o.locked[kv.first.as<std::string>()] = kv.second.as<double>();
    o.frame0 = xyz_rpy(u["frame0_in_base"]);
  } catch (const YAML::Exception& e) {
    throw UsageError(robot_yaml + ": the `urdf:` section: " + e.what());
  }
  return o;
}

// A body's parameters about a frame's origin: inertia J, first moment h, mass m.
struct Body {
  Matrix3d J = Matrix3d::Zero();
  Vector3d h = Vector3d::Zero();
  double m = 0;
};

// The body of a URDF inertial (its frame `Tc` in the reference frame).
Body body_of(const urdf::Inertial& in, const Isometry3d& Tc) {
  Matrix3d Ic;
  Ic << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const Vector3d c = Tc.translation();
  const Matrix3d R = Tc.linear();
  Body b;
  b.m = in.mass;
  b.h = in.mass * c;
  b.J = R * Ic * R.transpose() + in.mass * (c.squaredNorm() * Matrix3d::Identity() - c * c.transpose());
  return b;
}

// Mass, CoM and inertia about the CoM of a body given about a frame, in that frame; consistent
// when the mass is positive and the inertia about the CoM satisfies the triangle inequality.
struct ComForm {
  double m = 0;
  Vector3d c = Vector3d::Zero();
  Matrix3d Ic = Matrix3d::Zero();
  bool consistent = false;
};
ComForm com_form(const Body& b) {
  ComForm f;
  f.m = b.m;
  if (!(b.m > 0)) return f;
  f.c = b.h / b.m;
  f.Ic = b.J - b.m * (f.c.squaredNorm() * Matrix3d::Identity() - f.c * f.c.transpose());
  const Vector3d e = Eigen::SelfAdjointEigenSolver<Matrix3d>(0.5 * (f.Ic + f.Ic.transpose())).eigenvalues();
  const double tol = 1e-12 * std::max(1e-300, e.cwiseAbs().maxCoeff());
  f.consistent = e.minCoeff() >= -tol && e(0) + e(1) >= e(2) - tol;
  return f;
}

// The text of an element <tag ... name="name" ...>...</tag> (or self-closing), skipping
// comments; for joints only the real ones (with a type attribute, not a transmission's).
struct Span {
  std::size_t begin = std::string::npos, open_end = 0, end = 0;  // [begin, end); open_end after '>'
  bool self_closing = false;
};
Span find_element(const std::string& x, const std::string& tag, const std::string& name) {
  std::size_t at = 0;
  while ((at = x.find('<', at)) != std::string::npos) {
    if (x.compare(at, 4, "<!--") == 0) {
      const std::size_t e = x.find("-->", at);
      if (e == std::string::npos) break;
      at = e + 3;
      continue;
    }
    const std::size_t gt = x.find('>', at);
    if (gt == std::string::npos) break;
    const std::string head = x.substr(at, gt - at + 1);
    const bool is_tag = head.compare(0, tag.size() + 1, "<" + tag) == 0 &&
                        std::isspace(static_cast<unsigned char>(head[tag.size() + 1]));
    if (is_tag && head.find("name=\"" + name + "\"") != std::string::npos &&
        (tag != "joint" || head.find("type=") != std::string::npos)) {
      Span s;
      s.begin = at;
      s.open_end = gt + 1;
      s.self_closing = head.size() >= 2 && head[head.size() - 2] == '/';
      if (s.self_closing) {
        s.end = gt + 1;
        return s;
      }
      const std::size_t close = x.find("</" + tag + ">", gt);
      if (close == std::string::npos) break;
      s.end = close + tag.size() + 3;
      return s;
    }
    at = gt + 1;
  }
  return {};
}

// The span of a child element <tag ...>...</tag> or <tag .../> inside [from, to), or npos.
std::pair<std::size_t, std::size_t> find_child(const std::string& x, const std::string& tag, std::size_t from,
                                               std::size_t to) {
  std::size_t at = from;
  while ((at = x.find("<" + tag, at)) != std::string::npos && at < to) {
    const char next = x[at + tag.size() + 1];
    if (next == '>' || next == '/' || std::isspace(static_cast<unsigned char>(next))) {
      const std::size_t gt = x.find('>', at);
      if (x[gt - 1] == '/') return {at, gt + 1};
      const std::size_t close = x.find("</" + tag + ">", gt);
      return {at, close + tag.size() + 3};
    }
    at += 1;
  }
  return {std::string::npos, std::string::npos};
}

// The indentation of the line that holds position p.
std::string indent_at(const std::string& x, std::size_t p) {
  const std::size_t line = x.rfind('\n', p);
  const std::size_t start = line == std::string::npos ? 0 : line + 1;
  std::size_t e = start;
  while (e < x.size() && (x[e] == ' ' || x[e] == '\t')) ++e;
  return x.substr(start, e - start);
}

std::string num(double v) { return io::number_text(std::abs(v) < 1e-300 ? 0.0 : v); }

std::string inertial_xml(const ComForm& f, const std::string& indent) {
  const std::string i2 = indent + "  ";
  return "<inertial>\n" + i2 + "<origin xyz=\"" + num(f.c.x()) + " " + num(f.c.y()) + " " + num(f.c.z()) +
         "\" rpy=\"0 0 0\"/>\n" + i2 + "<mass value=\"" + num(f.m) + "\"/>\n" + i2 + "<inertia ixx=\"" +
         num(f.Ic(0, 0)) + "\" ixy=\"" + num(f.Ic(0, 1)) + "\" ixz=\"" + num(f.Ic(0, 2)) + "\" iyy=\"" +
         num(f.Ic(1, 1)) + "\" iyz=\"" + num(f.Ic(1, 2)) + "\" izz=\"" + num(f.Ic(2, 2)) + "\"/>\n" + indent +
         "</inertial>";
}

}  // namespace

std::string urdf_into(const model_export::UrdfDescription& d, const std::string& robot_yaml,
                      const std::string& user_urdf, std::vector<std::string>& notes) {
  const Origin origin = read_origin(robot_yaml);
  std::ifstream in(user_urdf, std::ios::binary);
  if (!in) throw UsageError(user_urdf + ": cannot read it");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string x = buffer.str();
  // Malformed XML where it is (urdfdom printed "line 100 in ./urdf_parser/src/model.cpp"), and
  // urdfdom's own messages in the error rather than on the console.
  {
    TiXmlDocument doc;
    doc.Parse(x.c_str());
    if (doc.Error())
      throw UsageError(
          fmt::format("{}:{}:{}: malformed XML: {}", user_urdf, doc.ErrorRow(), doc.ErrorCol(), doc.ErrorDesc()));
  }
  const console_bridge::LogLevel level = console_bridge::getLogLevel();
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(x);
  console_bridge::setLogLevel(level);
  if (!model) throw UsageError(user_urdf + ": not a valid URDF (symoroc model " + user_urdf + " says why)");
  const int n = static_cast<int>(d.joints.size());
  if (static_cast<int>(origin.joints.size()) != n || static_cast<int>(origin.links.size()) != n)
    throw UsageError(fmt::format("{}: `urdf:` lists {} joints, the model has {}", robot_yaml, origin.joints.size(), n));
  if (!model->getLink(origin.base_link))
    throw UsageError(user_urdf + ": no link '" + origin.base_link + "' (robot.yaml urdf base_link)");

  // Every link's pose at q = 0 (off-chain moving joints at their locked positions).
  std::map<std::string, Isometry3d> T;
  std::function<void(const urdf::Link&)> walk = [&](const urdf::Link& l) {
    for (const auto& c : l.child_links) {
      const urdf::Joint& j = *c->parent_joint;
      const auto lock = origin.locked.find(j.name);
      const Isometry3d motion = urdf_geometry::motion(j, lock == origin.locked.end() ? 0.0 : lock->second);
      T[c->name] = T[l.name] * pose(j.parent_to_joint_origin_transform) * motion;
      walk(*c);
    }
  };
  T[origin.base_link] = Isometry3d::Identity();
  walk(*model->getLink(origin.base_link));

  // The model frames at q = 0, in base-link coordinates.
  std::vector<Isometry3d> F(d.frames.size() + 1);
  F[0] = origin.frame0;
  for (std::size_t f = 0; f < d.frames.size(); ++f) F[f + 1] = F[d.frames[f].ant] * mdh_transform(d.frames[f], 0.0);

  int replaced = 0;
  for (int k = 1; k <= n; ++k) {
    const urdf::JointConstSharedPtr joint = model->getJoint(origin.joints[k - 1]);
    if (!joint)
      throw UsageError(fmt::format("{}: no joint '{}' (robot.yaml urdf joints)", user_urdf, origin.joints[k - 1]));
    const std::string chain_link = joint->child_link_name;
    // The URDF's joint must be the model's: its axis along frame k's z and, for a revolute
    // joint, on that line. Another arm's URDF (an origin changed) would get inertials computed
    // for this arm's frames, silently.
    if (T.count(joint->parent_link_name)) {
      const Isometry3d J = T[joint->parent_link_name] * pose(joint->parent_to_joint_origin_transform);
      const Vector3d a = (J.linear() * Vector3d(joint->axis.x, joint->axis.y, joint->axis.z)).normalized();
      const Vector3d z = F[k].linear().col(2), o = F[k].translation(), r = J.translation() - o;
      const double angle = std::acos(std::min(1.0, std::abs(a.dot(z))));
      const double off = joint->type == urdf::Joint::PRISMATIC ? 0.0 : (r - r.dot(z) * z).norm();
      if (!(angle <= 1e-6) || !(off <= 1e-6))
        throw UsageError(
            fmt::format("{}: joint '{}' is not the model's joint {}: its axis is {:.4g} deg from the model's and "
                        "{:.4g} mm off it. This URDF's geometry differs from the one symoroc model read ({}'s "
                        "`urdf:` record); export into that URDF, or model this one",
                        user_urdf, joint->name, k, angle * 180 / M_PI, off * 1e3, robot_yaml));
    }
    // The identified body of model link k, about frame k's origin.
    model_export::UrdfInertial id = model_export::link_inertial(d, k);
    Body identified;
    if (id.present) model_export::inertial_about_origin(id, identified.J, identified.h, identified.m);
    // Minus the merged links' own inertials.
    Body rest = identified;
    std::vector<std::string> merged;
    for (const auto& name : origin.links[k - 1]) {
      if (name == chain_link) continue;
      const auto l = model->getLink(name);
      if (!l) throw UsageError(fmt::format("{}: no link '{}' (robot.yaml urdf links)", user_urdf, name));
      if (!T.count(name))
        throw UsageError(fmt::format("{}: link '{}' is not under '{}'", user_urdf, name, origin.base_link));
      if (!l->inertial || l->inertial->mass == 0) continue;
      const Body b = body_of(*l->inertial, F[k].inverse() * T[name] * pose(l->inertial->origin));
      rest.J -= b.J;
      rest.h -= b.h;
      rest.m -= b.m;
      merged.push_back(name);
    }
    bool whole = false;
    ComForm f = com_form(rest);
    if (!merged.empty() && !f.consistent) {
      whole = true;
      f = com_form(identified);
      notes.push_back(
          fmt::format("model link {}: the identified body less the merged links' inertials ({}) is not physically "
                      "consistent: {} takes the whole body and their <inertial> are removed",
                      k, fmt::join(merged, ", "), chain_link));
    }
    // Into the chain link's own frame.
    const Isometry3d L = F[k].inverse() * T[chain_link];  // the chain link in frame k
    ComForm g = f;
    g.c = L.inverse() * f.c;
    g.Ic = L.linear().transpose() * f.Ic * L.linear();
    Span link = find_element(x, "link", chain_link);
    if (link.begin == std::string::npos) throw UsageError(user_urdf + ": no <link name=\"" + chain_link + "\">");
    const std::string indent = indent_at(x, link.begin) + "  ";
    const std::string block = f.m > 0 ? inertial_xml(g, indent) : std::string();
    if (link.self_closing) {
      if (!block.empty()) {
        const std::string head = x.substr(link.begin, link.end - link.begin - 2);  // without "/>"
        x.replace(link.begin, link.end - link.begin,
                  head + ">\n" + indent + block + "\n" + indent_at(x, link.begin) + "</link>");
      }
    } else {
      const auto [b, e] = find_child(x, "inertial", link.open_end, link.end);
      if (b != std::string::npos) {
        x.replace(b, e - b, block);
      } else if (!block.empty()) {
        x.insert(link.open_end, "\n" + indent + block);
      }
    }
    ++replaced;
    if (whole)
      for (const auto& name : merged) {
        const Span s = find_element(x, "link", name);
        auto [b, e] = find_child(x, "inertial", s.open_end, s.end);
        if (b == std::string::npos) continue;
        while (b > 0 && (x[b - 1] == ' ' || x[b - 1] == '\t')) --b;  // the element's whole line
        if (e < x.size() && x[e] == '\n') ++e;
        x.erase(b, e - b);
      }
    // The joint's friction.
    bool has_fv = false, has_fs = false;
    double fv = 0, fs = 0;
    for (Eigen::Index i = 0; i < d.s.size(); ++i) {
      const auto& p = d.names[static_cast<std::size_t>(i)];
      if (p.joint != k) continue;
      if (std::string(p.family) == "FV") has_fv = true, fv = d.s(i);
      if (std::string(p.family) == "FS") has_fs = true, fs = d.s(i);
    }
    if (has_fv || has_fs) {
      const Span js = find_element(x, "joint", joint->name);
      if (js.begin == std::string::npos || js.self_closing)
        throw UsageError(user_urdf + ": no <joint name=\"" + joint->name + "\">");
      const std::string dyn = "<dynamics damping=\"" + num(fv) + "\" friction=\"" + num(fs) + "\"/>";
      const auto [b, e] = find_child(x, "dynamics", js.open_end, js.end);
      if (b != std::string::npos) {
        x.replace(b, e - b, dyn);
      } else {
        const std::size_t close = js.end - std::string("</joint>").size();
        x.insert(close, "  " + dyn + "\n" + indent_at(x, js.begin));  // before </joint>, one level in
      }
    }
  }
  notes.push_back(fmt::format(
      "{} chain links' <inertial> and their joints' <dynamics> written into {}; every other line is unchanged",
      replaced, user_urdf));
  return x;
}

}  // namespace symoro::dynid
