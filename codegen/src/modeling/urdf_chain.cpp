#include "urdf_chain.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include "equation_text.hpp"
#include "urdf_checks.hpp"
#include "symoro/codegen/robot_spec.hpp"
#include "symoro/detail/regular_file.hpp"
#include "symoro/urdf_geometry.hpp"

namespace symoro::codegen::modeling {

namespace {

using urdf_geometry::exact;
using urdf_geometry::kAngleSnap;
using urdf_geometry::pose;
using urdf_geometry::snapped_angle;
using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kLengthSnap = 1e-12;  // m

// urdfdom reports through console_bridge: the messages go into the error instead of stderr.
class Capture : public console_bridge::OutputHandler {
 public:
  Capture() { console_bridge::useOutputHandler(this); }
  ~Capture() override { console_bridge::restorePreviousOutputHandler(); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages += (messages.empty() ? "" : "; ") + text;
  }
  std::string messages;
};



Vector3d vec(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

bool moving(const urdf::Joint& j) { return j.type != urdf::Joint::FIXED; }

// An angle as .par text: exact multiples of pi/2 by name.
std::string angle_text(double a) {
  const double k = std::round(a / (M_PI / 2));
  if (std::abs(a - k * M_PI / 2) <= kAngleSnap) {
    const int q = static_cast<int>(k);
    switch (q) {
      case 0: return "0";
      case 1: return "pi/2";
      case -1: return "-pi/2";
      case 2: return "pi";
      case -2: return "-pi";
    }
  }
  return number_text(a);
}
// A length: 0 below kLengthSnap, else the 12-digit decimal it is within rounding of (the URDF's
// decimals come back as 0.0825 rather than 0.08250000000000005).
double snapped_length(double x) {
  if (std::abs(x) <= kLengthSnap) return 0.0;
  char t[40];
  std::snprintf(t, sizeof t, "%.12g", x);
  const double r = std::strtod(t, nullptr);
  return std::abs(r - x) <= 1e-13 * std::abs(x) ? r : x;
}

std::string identifier(const std::string& s) {
  std::string out;
  for (const char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "_" + out;
  return out;
}

struct Dh {
  int sigma = 0;
  double gamma = 0, b = 0, alpha = 0, d = 0, theta = 0, r = 0;
};

Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Vector3d::UnitZ()).toRotationMatrix(); }
Matrix3d rot_x(double a) { return Eigen::AngleAxisd(a, Vector3d::UnitX()).toRotationMatrix(); }

// ant T j at q = 0 (theta is the joint variable of a revolute joint, r of a prismatic one).
Isometry3d dh_transform(const Dh& p) {
  const double theta = p.sigma == 0 ? 0 : p.theta, r = p.sigma == 1 ? 0 : p.r;
  Isometry3d T = Isometry3d::Identity();
  T.linear() = rot_z(p.gamma) * rot_x(p.alpha) * rot_z(theta);
  T.translation() = rot_z(p.gamma) * Vector3d(p.d, -r * std::sin(p.alpha), p.b + r * std::cos(p.alpha));
  return T;
}



std::string xyz_rpy(const Isometry3d& T) {
  const Vector3d p = T.translation();
  const Matrix3d R = T.linear();
  // URDF's fixed-axis roll, pitch, yaw: R = Rz(y) Ry(p) Rx(r).
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
  double roll, yaw;
  if (std::abs(std::cos(pitch)) > 1e-9) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {
    roll = 0;
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  auto n = [](double x) { return number_text(std::abs(x) < 1e-15 ? 0.0 : x); };
  return "{xyz: [" + n(p.x()) + ", " + n(p.y()) + ", " + n(p.z()) + "], rpy: [" + n(roll) + ", " + n(pitch) + ", " + n(yaw) + "]}";
}

// A URDF is a few elements deep (robot > link > inertial > origin); a file nested far deeper is
// no URDF, and the XML parser's recursion would overflow the stack on it (a segmentation fault
// after 18 s at 100,000 levels). The first element past kMaxXmlDepth, or 0 when none is.
constexpr int kMaxXmlDepth = 100;
int too_deep_line(const std::string& text) {
  int depth = 0, line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (c != '<') continue;
    auto skip_to = [&](const char* end) {  // past `end`, counting lines
      const std::size_t at = text.find(end, i);
      const std::size_t stop = at == std::string::npos ? text.size() : at + std::strlen(end);
      line += static_cast<int>(std::count(text.begin() + static_cast<std::ptrdiff_t>(i), text.begin() + static_cast<std::ptrdiff_t>(stop), '\n'));
      i = stop - 1;
    };
    if (text.compare(i, 4, "<!--") == 0) { skip_to("-->"); continue; }
    if (text.compare(i, 9, "<![CDATA[") == 0) { skip_to("]]>"); continue; }
    if (text.compare(i, 2, "<?") == 0 || text.compare(i, 2, "<!") == 0) { skip_to(">"); continue; }
    const bool closing = i + 1 < text.size() && text[i + 1] == '/';
    // The tag's end, past quoted attribute values.
    std::size_t k = i + 1;
    char quote = 0;
    for (; k < text.size(); ++k) {
      if (text[k] == '\n') ++line;
      if (quote) {
        if (text[k] == quote) quote = 0;
      } else if (text[k] == '"' || text[k] == '\'') {
        quote = text[k];
      } else if (text[k] == '>') {
        break;
      }
    }
    const bool self_closing = k < text.size() && k > i && text[k - 1] == '/';
    if (closing) --depth;
    else if (!self_closing && ++depth > kMaxXmlDepth) return line;
    i = k;
  }
  return 0;
}

// A serial arm's URDF has tens of links; the chain's search and the model's generation grow with
// their number (20,000 links ran for minutes).
constexpr std::size_t kMaxUrdfLinks = 2000;
constexpr int kMaxChainJoints = 64;

}  // namespace

UrdfChain read_urdf_chain(const std::string& path, const ModelingOptions& options) {
  if (const std::string why = ::symoro::detail::not_a_regular_file(path); !why.empty()) throw InputError(path, 0, 0, why);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, 0, "cannot read the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  // The line of an element, for messages: the first `name="..."` after `<tag`.
  auto line_of = [&](const std::string& tag, const std::string& name) {
    std::size_t at = 0;
    while ((at = text.find("<" + tag, at)) != std::string::npos) {
      const std::size_t end = text.find('>', at);
      const std::size_t n = text.find("name=\"" + name + "\"", at);
      if (n != std::string::npos && n < end) return static_cast<int>(std::count(text.begin(), text.begin() + at, '\n')) + 1;
      at += 1;
    }
    return 0;
  };
  if (const int line = too_deep_line(text))
    throw InputError(path, line, 0, "elements nested more than " + std::to_string(kMaxXmlDepth) + " deep: not a URDF");
  // Malformed XML is reported where it is (urdfdom says only that parsing failed).
  {
    TiXmlDocument doc;
    doc.Parse(text.c_str());
    if (doc.Error()) throw InputError(path, doc.ErrorRow(), doc.ErrorCol(), std::string("malformed XML: ") + doc.ErrorDesc());
    check_urdf_values(doc, path);
  }
  urdf::ModelInterfaceSharedPtr model;
  {
    Capture capture;
    model = urdf::parseURDF(text);
    if (!model) throw InputError(path, 0, 0, "not a valid URDF" + (capture.messages.empty() ? std::string() : ": " + capture.messages));
  }
  if (model->links_.size() > kMaxUrdfLinks)
    throw InputError(path, 0, 0, std::to_string(model->links_.size()) + " links: more than the " + std::to_string(kMaxUrdfLinks) +
                                     " a robot description may have here (symoroc models serial arms)");
  auto link = [&](const std::string& name, const char* what) {
    urdf::LinkConstSharedPtr l = model->getLink(name);
    if (!l) throw InputError(path, 0, 0, std::string(what) + " '" + name + "' is not a link of the URDF");
    return l;
  };
  const urdf::LinkConstSharedPtr base = options.base_link.empty() ? model->getRoot() : link(options.base_link, "the base link");

  // The subtree under a joint has a moving joint (the joint itself included).
  std::function<bool(const urdf::Link&)> has_moving = [&](const urdf::Link& l) {
    for (const auto& j : l.child_joints)
      if (moving(*j)) return true;
    for (const auto& c : l.child_links)
      if (has_moving(*c)) return true;
    return false;
  };
  urdf::LinkConstSharedPtr tip;
  if (!options.tip_link.empty()) {
    tip = link(options.tip_link, "the tip link");
    urdf::LinkConstSharedPtr up = tip;
    while (up && up != base) up = up->getParent();
    if (!up) throw InputError(path, line_of("link", tip->name), 0, "the tip link '" + tip->name + "' is not below the base link '" + base->name + "'");
  } else {
    tip = base;
    for (;;) {
      std::vector<urdf::LinkSharedPtr> next;
      for (std::size_t c = 0; c < tip->child_links.size(); ++c) {
        const auto& child = tip->child_links[c];
        if (moving(*child->parent_joint) || has_moving(*child)) next.push_back(child);
      }
      if (next.empty()) break;
      if (next.size() > 1)
        throw InputError(path, line_of("link", tip->name), 0,
                         "the link '" + tip->name + "' branches into moving joints ('" + next[0]->parent_joint->name + "' and '" +
                             next[1]->parent_joint->name + "'): name the chain's end with --tip-link");
      tip = next[0];
    }
  }

  // The chain's joints, base to tip.
  std::vector<urdf::JointConstSharedPtr> path_joints;
  for (urdf::LinkConstSharedPtr l = tip; l != base; l = l->getParent()) path_joints.insert(path_joints.begin(), l->parent_joint);
  std::vector<urdf::JointConstSharedPtr> chain;
  std::set<std::string> on_chain;
  for (const auto& j : path_joints) {
    const int line = line_of("joint", j->name);
    switch (j->type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
      case urdf::Joint::PRISMATIC: break;
      case urdf::Joint::FIXED: continue;
      default:
        throw InputError(path, line, 0, "joint '" + j->name + "' on the chain is " +
                                            (j->type == urdf::Joint::FLOATING ? "floating" : j->type == urdf::Joint::PLANAR ? "planar" : "of an unknown type") +
                                            ": only revolute, continuous and prismatic joints are supported");
    }
    if (j->mimic) throw InputError(path, line, 0, "joint '" + j->name + "' on the chain mimics '" + j->mimic->joint_name + "': a chain joint must be independent");
    if (vec(j->axis).norm() < 1e-12) throw InputError(path, line, 0, "joint '" + j->name + "' has a zero axis");
    chain.push_back(j);
    on_chain.insert(j->name);
  }
  const int n = static_cast<int>(chain.size());
  if (n == 0) throw InputError(path, 0, 0, "no moving joint between '" + base->name + "' and '" + tip->name + "'");
  if (n > kMaxChainJoints)
    throw InputError(path, line_of("joint", chain[kMaxChainJoints]->name), 0,
                     std::to_string(n) + " moving joints between '" + base->name + "' and '" + tip->name + "': symoroc models serial arms of at most " +
                         std::to_string(kMaxChainJoints));
  for (const auto& [name, value] : options.locked) {
    const auto j = model->getJoint(name);
    if (!j || !moving(*j) || on_chain.count(name))
      throw InputError(path, j ? line_of("joint", name) : 0, 0, "--lock " + name + ": not a moving joint off the chain");
    const std::string lock = "--lock " + name + "=" + number_text(value);
    if (!std::isfinite(value) || std::abs(value) > 1e3) throw InputError(path, line_of("joint", name), 0, lock + ": not a position");
    const bool bounded = j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::PRISMATIC;
    if (bounded && j->limits && j->limits->lower <= j->limits->upper &&
        (value < j->limits->lower || value > j->limits->upper))
      throw InputError(path, line_of("joint", name), 0,
                       lock + ": outside the joint's limits " + number_text(j->limits->lower) + " .. " + number_text(j->limits->upper));
  }

  // Every link under the base at q = 0 (off-chain moving joints at their locked positions), and
  // the chain link (body) each is rigidly part of.
  UrdfChain out;
  std::map<std::string, Isometry3d> T;
  std::map<std::string, int> body;
  std::vector<std::string> locked_notes;
  std::function<void(const urdf::Link&)> walk = [&](const urdf::Link& l) {
    for (const auto& c : l.child_links) {
      const urdf::Joint& j = *c->parent_joint;
      Isometry3d motion = Isometry3d::Identity();
      int b = body[l.name];
      if (on_chain.count(j.name)) {
        for (int k = 0; k < n; ++k)
          if (chain[k]->name == j.name) b = k + 1;
      } else if (moving(j)) {
        if (j.type != urdf::Joint::PRISMATIC && j.type != urdf::Joint::REVOLUTE && j.type != urdf::Joint::CONTINUOUS)
          throw InputError(path, line_of("joint", j.name), 0, "joint '" + j.name + "' off the chain is floating or planar: it cannot be locked");
        const auto it = options.locked.find(j.name);
        const double q = it == options.locked.end() ? 0.0 : it->second;
        motion = urdf_geometry::motion(j, q);
        locked_notes.push_back(j.name + " = " + number_text(q));
      }
      T[c->name] = T[l.name] * pose(j.parent_to_joint_origin_transform) * motion;
      body[c->name] = b;
      walk(*c);
    }
  };
  T[base->name] = Isometry3d::Identity();
  body[base->name] = 0;
  walk(*base);
  if (!locked_notes.empty()) {
    std::string s = "off-chain moving joints locked (merged into the link they hang from):";
    for (const auto& l : locked_notes) s += " " + l;
    out.notes.push_back(s);
  }

  // ---- modified DH frames (in base-link coordinates at q = 0)
  std::vector<Vector3d> P(n), u(n);
  for (int k = 0; k < n; ++k) {
    const Isometry3d& Tc = T[chain[k]->child_link_name];
    P[k] = Tc.translation();
    u[k] = Tc.linear() * vec(chain[k]->axis).normalized();
  }
  // The point of line k closest to line k+1 (on a parallel line k+1: the foot of P_{k+1}).
  auto closest_on = [&](const Vector3d& p1, const Vector3d& d1, const Vector3d& p2, const Vector3d& d2) {
    const Vector3d w = p1 - p2;
    const double b = d1.dot(d2), den = 1 - b * b;
    if (den < 1e-12) return Vector3d(p1 + (p2 - p1).dot(d1) * d1);
    const double s = (b * d2.dot(w) - d1.dot(w)) / den;
    return Vector3d(p1 + s * d1);
  };
  std::vector<Dh> dh(n);
  Matrix3d R_prev;
  Vector3d O_prev;
  {
    const Vector3d z0 = u[0];
    Vector3d x0 = Vector3d::UnitX() - Vector3d::UnitX().dot(z0) * z0;
    if (x0.norm() < 0.1) x0 = Vector3d::UnitY() - Vector3d::UnitY().dot(z0) * z0;
    x0.normalize();
    R_prev.col(0) = x0;
    R_prev.col(1) = z0.cross(x0);
    R_prev.col(2) = z0;
    O_prev = chain[0]->type == urdf::Joint::PRISMATIC || n == 1 ? P[0] : closest_on(P[0], u[0], P[1], u[1]);
  }
  const Isometry3d frame0 = [&] {
    Isometry3d f = Isometry3d::Identity();
    f.linear() = R_prev;
    f.translation() = O_prev;
    return f;
  }();
  for (int k = 0; k < n; ++k) {
    const Vector3d xi = R_prev.col(0), zi = R_prev.col(2), zk = u[k];
    Vector3d A, B, xp;
    double d = 0;
    const Vector3d c = zi.cross(zk);
    if (c.norm() > 1e-7) {  // axes closer to parallel than that are parallel (see kAngleSnap)
      A = closest_on(O_prev, zi, P[k], zk);
      B = closest_on(P[k], zk, O_prev, zi);
      const Vector3d w = B - A;
      if (w.norm() > kLengthSnap) {
        xp = w.normalized();
        d = w.norm();
      } else {
        xp = c.normalized();
        B = A;
      }
    } else {
      A = O_prev;
      const Vector3d w = (P[k] - O_prev) - (P[k] - O_prev).dot(zi) * zi;
      if (w.norm() > kLengthSnap) {
        xp = w.normalized();
        d = w.norm();
      } else {
        xp = xi;
      }
      B = A + w;
    }
    Dh& p = dh[k];
    p.sigma = chain[k]->type == urdf::Joint::PRISMATIC ? 1 : 0;
    p.gamma = snapped_angle(std::atan2(xi.cross(xp).dot(zi), xi.dot(xp)));
    p.b = snapped_length((A - O_prev).dot(zi));
    p.alpha = snapped_angle(std::atan2(zi.cross(zk).dot(xp), zi.dot(zk)));
    p.d = snapped_length(d);
    Vector3d Ok = B;
    if (p.sigma == 0 && k + 1 < n) Ok = closest_on(P[k], zk, P[k + 1], u[k + 1]);
    p.r = p.sigma == 0 ? snapped_length((Ok - B).dot(zk)) : 0.0;
    p.theta = 0;
    // The frame from the rounded parameters, so that everything below agrees with the model.
    Isometry3d prev = Isometry3d::Identity();
    prev.linear() = R_prev;
    prev.translation() = O_prev;
    Isometry3d Tk = prev * dh_transform(p);
    for (int a = 0; a < 3; ++a)
      for (int bb = 0; bb < 3; ++bb) Tk.linear()(a, bb) = exact(Tk.linear()(a, bb));
    if ((Tk.linear().col(2) - zk).norm() > 1e-6 || (Tk.translation() - Ok).norm() > 1e-6)
      throw std::logic_error("symoroc model: the DH frame of joint '" + chain[k]->name + "' does not reproduce its axis (an internal error)");
    R_prev = Tk.linear();
    O_prev = Tk.translation();
  }
  // Frames 1..n again, at q = 0, from the rounded parameters.
  std::vector<Isometry3d> F(n + 1);
  F[0] = frame0;
  for (int k = 0; k < n; ++k) F[k + 1] = F[k] * dh_transform(dh[k]);

  // ---- inertials: every URDF link's, summed into its chain link, about the DH frame's origin
  struct Body {
    double m = 0;
    Vector3d ms = Vector3d::Zero();
    Matrix3d J = Matrix3d::Zero();
    std::vector<std::string> links;
  };
  std::vector<Body> bodies(n + 1);
  std::vector<std::string> massless, inconsistent;
  for (const auto& [name, Tl] : T) {
    const int b = body[name];
    bodies[b].links.push_back(name);
    const auto l = model->getLink(name);
    if (!l->inertial || l->inertial->mass == 0) {
      if (b > 0) massless.push_back(name);
      continue;
    }
    const urdf::Inertial& I = *l->inertial;
    Matrix3d Ic;
    Ic << I.ixx, I.ixy, I.ixz, I.ixy, I.iyy, I.iyz, I.ixz, I.iyz, I.izz;
    const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(Ic);
    const Vector3d e = eig.eigenvalues();
    if (I.mass < 0 || e.minCoeff() < 0 || e(0) + e(1) < e(2) - 1e-12 * e.maxCoeff()) inconsistent.push_back(name);
    if (b == 0) continue;
    const Isometry3d Tc = Tl * pose(I.origin);  // the inertial frame in base coordinates
    const Isometry3d inF = F[b].inverse() * Tc;  // ... in DH frame b
    const Vector3d c = inF.translation();
    const Matrix3d Jc = inF.linear() * Ic * inF.linear().transpose();
    Body& B = bodies[b];
    B.m += I.mass;
    B.ms += I.mass * c;
    B.J += Jc + I.mass * (c.squaredNorm() * Matrix3d::Identity() - c * c.transpose());
  }
  if (!massless.empty()) {
    std::string s = "links without <inertial> (prior 0):";
    for (const auto& m : massless) s += " " + m;
    out.notes.push_back(s);
  }
  for (const auto& name : inconsistent)
    out.notes.push_back("warning: the inertial of link '" + name + "' (line " + std::to_string(line_of("link", name)) +
                        ") is not physically consistent (a negative mass or principal moment, or the triangle inequality broken)");

  // ---- the .par
  const std::string given_name = options.name.empty() ? model->getName() : options.name;
  out.name = identifier(given_name);
  if (out.name != given_name)
    out.notes.push_back("warning: the robot's name '" + given_name + "' is no C++ identifier: written as '" + out.name + "'");
  auto column = [&](auto get) {
    std::string s = "{";
    for (int k = 0; k < n; ++k) s += (k ? "," : "") + get(k);
    return s + "}";
  };
  auto named = [&](const std::string& fam, bool on) {
    return column([&](int k) { return on ? fam + std::to_string(k + 1) : std::string("0"); });
  };
  const Vector3d g0 = frame0.linear().transpose() * Vector3d(0, 0, -1);
  auto gravity = [&](double v) {
    v = exact(v);
    if (std::abs(v) < 1e-15) return std::string("0");
    if (v == 1) return std::string("G3");
    if (v == -1) return std::string("-G3");
    return number_text(v) + "*G3";
  };
  std::string par = "(* Robotname = '" + out.name + "' *)\n";
  par += "(* Written by symoroc model from " + path + ", base link " + base->name + ", tip link " + tip->name + " *)\n";
  par += "NL = " + std::to_string(n) + "\nNJ = " + std::to_string(n) + "\nNF = " + std::to_string(n) +
         "\nType = 0\nis_floating = False\nis_mobile = False\n\n(* Geometric parameters *)\n";
  par += "ant = " + column([&](int k) { return std::to_string(k); }) + "\n";
  par += "sigma = " + column([&](int k) { return std::to_string(dh[k].sigma); }) + "\n";
  par += "b = " + column([&](int k) { return number_text(dh[k].b); }) + "\n";
  par += "d = " + column([&](int k) { return number_text(dh[k].d); }) + "\n";
  par += "r = " + column([&](int k) { return dh[k].sigma ? "r" + std::to_string(k + 1) : number_text(dh[k].r); }) + "\n";
  par += "gamma = " + column([&](int k) { return angle_text(dh[k].gamma); }) + "\n";
  par += "alpha = " + column([&](int k) { return angle_text(dh[k].alpha); }) + "\n";
  par += "mu = " + column([&](int) { return std::string("1"); }) + "\n";
  par += "theta = " + column([&](int k) { return dh[k].sigma ? angle_text(dh[k].theta) : "th" + std::to_string(k + 1); }) + "\n";
  par += "\n(* Dynamic parameters and external forces *)\n";
  for (const char* fam : {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"}) par += std::string(fam) + " = " + named(fam, true) + "\n";
  par += "IA = " + named("IA", options.rotor_inertia) + "\nFV = " + named("FV", options.viscous) + "\nFS = " + named("FS", options.coulomb) + "\n";
  for (const char* f : {"FX", "FY", "FZ", "CX", "CY", "CZ"}) par += std::string(f) + " = " + named("", false) + "\n";
  par += "\n(* Joint parameters *)\neta = " + named("", false) + "\nk = " + named("", false) + "\n";
  par += "QP = " + named("QP", true) + "\nQDP = " + named("QDP", true) + "\nGAM = " + named("GAM", true) + "\n";
  par += "\n(* Velocity and acceleration of the base *)\nW0 = {0,0,0}\nWP0 = {0,0,0}\nV0 = {0,0,0}\nVP0 = {0,0,0}\n";
  par += "\n(* Acceleration of gravity: -z of the URDF's base link, in frame 0 *)\nG = {" + gravity(g0.x()) + "," + gravity(g0.y()) +
         "," + gravity(g0.z()) + "}\n";
  par += "\n(* Transformation of 0 frame position fT0 *)\nZ = {1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1}\n\n(* End of definition *)\n";
  out.par_text = par;

  // ---- robot.yaml
  std::string y = "# " + out.name + ": written by symoroc model from " + path + " (base link " + base->name + ", tip link " +
                  tip->name + ").\n# Review the joint limits; the nominal parameters are the URDF's inertials in the model's frames.\n";
  y += "description: " + model->getName() + " from its URDF\n\nconstants:\n  G3: 9.81        # m/s^2\n\njoints:\n";
  bool prismatic = false;
  for (int k = 0; k < n; ++k) {
    const urdf::Joint& j = *chain[k];
    prismatic = prismatic || j.type == urdf::Joint::PRISMATIC;
    double lower = -2 * M_PI, upper = 2 * M_PI, velocity = 0, effort = 0;
    if (j.limits) {
      if (j.type != urdf::Joint::CONTINUOUS) {
        lower = j.limits->lower;
        upper = j.limits->upper;
      }
      velocity = j.limits->velocity;
      effort = j.limits->effort;
    }
    std::string comment;
    if (j.type == urdf::Joint::CONTINUOUS) comment += " continuous: +-2 pi written;";
    if (!(lower < upper)) {
      comment += " the URDF's limits are empty: +-pi written;";
      out.notes.push_back("warning: joint '" + j.name + "' (line " + std::to_string(line_of("joint", j.name)) + ") has empty limits (" +
                          number_text(lower) + " .. " + number_text(upper) + "): robot.yaml gets -pi .. pi");
      lower = -M_PI;
      upper = M_PI;
    }
    if (identifier(j.name) != j.name)
      out.notes.push_back("warning: joint '" + j.name + "' (line " + std::to_string(line_of("joint", j.name)) +
                          ") is no C++ identifier: robot.yaml names it '" + identifier(j.name) + "'");
    if (!(velocity > 0)) {
      velocity = 1;
      comment += " no velocity limit in the URDF: 1 written;";
    }
    if (!(effort > 0)) {
      effort = 1;
      comment += " no effort limit in the URDF: 1 written;";
    }
    y += "  - {name: " + identifier(j.name) + ", lower: " + number_text(lower) + ", upper: " + number_text(upper) +
         ", velocity: " + number_text(velocity) + ", effort: " + number_text(effort) + "}" +
         (comment.empty() ? "" : "  #" + comment.substr(0, comment.size() - 1)) + "\n";
  }
  y += "\nparameter_units:\n  revolute: {XX: kg*m^2, XY: kg*m^2, XZ: kg*m^2, YY: kg*m^2, YZ: kg*m^2, ZZ: kg*m^2,\n"
       "             MX: kg*m, MY: kg*m, MZ: kg*m, M: kg, IA: kg*m^2, FV: N*m*s/rad, FS: N*m}\n";
  if (prismatic) y += "  prismatic: {IA: kg, FV: N*s/m, FS: N}\n";
  y += "\n# The URDF's values (a prior): standard parameters in the model's frames (kg, m, s, rad).\nnominal:\n";
  for (int k = 1; k <= n; ++k) {
    const Body& B = bodies[k];
    const std::string s = std::to_string(k);
    auto v = [](double x) { return number_text(std::abs(x) < 1e-300 ? 0.0 : x); };
    y += "  XX" + s + ": " + v(B.J(0, 0)) + "\n  XY" + s + ": " + v(B.J(0, 1)) + "\n  XZ" + s + ": " + v(B.J(0, 2)) + "\n  YY" + s +
         ": " + v(B.J(1, 1)) + "\n  YZ" + s + ": " + v(B.J(1, 2)) + "\n  ZZ" + s + ": " + v(B.J(2, 2)) + "\n  MX" + s + ": " +
         v(B.ms.x()) + "\n  MY" + s + ": " + v(B.ms.y()) + "\n  MZ" + s + ": " + v(B.ms.z()) + "\n  M" + s + ": " + v(B.m) + "\n";
    const auto& dyn = chain[k - 1]->dynamics;
    if (options.rotor_inertia) y += "  IA" + s + ": 0\n";
    if (options.viscous) y += "  FV" + s + ": " + v(dyn ? dyn->damping : 0.0) + "\n";
    if (options.coulomb) y += "  FS" + s + ": " + v(dyn ? dyn->friction : 0.0) + "\n";
  }
  y += "\n# Where the model's frames are in the URDF, and which URDF links each model link merges.\nurdf:\n";
  y += "  file: " + std::string(path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1)) + "\n";
  y += "  base_link: " + base->name + "\n  tip_link: " + tip->name + "\n";
  y += "  frame0_in_base: " + xyz_rpy(frame0) + "\n";
  y += "  tip_in_last_frame: " + xyz_rpy(F[n].inverse() * T[tip->name]) + "\n";
  y += "  joints: [";
  for (int k = 0; k < n; ++k) y += (k ? ", " : "") + chain[k]->name;
  y += "]\n  links:\n";
  for (int k = 1; k <= n; ++k) {
    y += "    - [";
    for (std::size_t i = 0; i < bodies[k].links.size(); ++i) y += (i ? ", " : "") + bodies[k].links[i];
    y += "]\n";
  }
  if (!options.locked.empty() || !locked_notes.empty()) {
    y += "  locked: {";
    bool first = true;
    std::function<void(const urdf::Link&)> list_locked = [&](const urdf::Link& l) {
      for (const auto& c : l.child_links) {
        const urdf::Joint& j = *c->parent_joint;
        if (moving(j) && !on_chain.count(j.name)) {
          const auto it = options.locked.find(j.name);
          y += (first ? "" : ", ") + j.name + ": " + number_text(it == options.locked.end() ? 0.0 : it->second);
          first = false;
        }
        list_locked(*c);
      }
    };
    list_locked(*base);
    y += "}\n";
  }
  out.robot_yaml = y;
  return out;
}

}  // namespace symoro::codegen::modeling
