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
#include "urdf_chain_parts.hpp"

namespace symoro::codegen::modeling {

namespace {

using namespace urdf_parts;
using urdf_geometry::exact;
using urdf_geometry::kAngleSnap;
using urdf_geometry::pose;
using urdf_geometry::snapped_angle;

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

// A length: 0 below kLengthSnap, else the 12-digit decimal it is within rounding of (the URDF's
// decimals come back as 0.0825 rather than 0.08250000000000005).
double snapped_length(double x) {
  if (std::abs(x) <= kLengthSnap) return 0.0;
  char t[40];
  std::snprintf(t, sizeof t, "%.12g", x);
  const double r = std::strtod(t, nullptr);
  return std::abs(r - x) <= 1e-13 * std::abs(x) ? r : x;
}

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
      line += static_cast<int>(std::count(text.begin() + static_cast<std::ptrdiff_t>(i),
                                          text.begin() + static_cast<std::ptrdiff_t>(stop), '\n'));
      i = stop - 1;
    };
    if (text.compare(i, 4, "<!--") == 0) {
      skip_to("-->");
      continue;
    }
    if (text.compare(i, 9, "<![CDATA[") == 0) {
      skip_to("]]>");
      continue;
    }
    if (text.compare(i, 2, "<?") == 0 || text.compare(i, 2, "<!") == 0) {
      skip_to(">");
      continue;
    }
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
    if (closing)
      --depth;
    else if (!self_closing && ++depth > kMaxXmlDepth)
      return line;
    i = k;
  }
  return 0;
}

// A serial arm's URDF has tens of links; the chain's search and the model's generation grow with
// their number (20,000 links ran for minutes).
constexpr std::size_t kMaxUrdfLinks = 2000;
constexpr int kMaxChainJoints = 64;

// The file read and checked: nesting depth, well-formed XML, values (urdf_checks.hpp), urdfdom's
// own parse, the number of links.
UrdfSource read_urdf_source(const std::string& path) {
  if (const std::string why = ::symoro::detail::not_a_regular_file(path); !why.empty())
    throw InputError(path, 0, 0, why);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, 0, "cannot read the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  UrdfSource src;
  src.path = path;
  src.text = buffer.str();
  const std::string& text = src.text;
  if (const int line = too_deep_line(text))
    throw InputError(path, line, 0, "elements nested more than " + std::to_string(kMaxXmlDepth) + " deep: not a URDF");
  // Malformed XML is reported where it is (urdfdom says only that parsing failed).
  {
    TiXmlDocument doc;
    doc.Parse(text.c_str());
    if (doc.Error())
      throw InputError(path, doc.ErrorRow(), doc.ErrorCol(), std::string("malformed XML: ") + doc.ErrorDesc());
    check_urdf_values(doc, path);
  }
  {
    Capture capture;
    src.model = urdf::parseURDF(text);
    if (!src.model)
      throw InputError(path, 0, 0,
                       "not a valid URDF" + (capture.messages.empty() ? std::string() : ": " + capture.messages));
  }
  if (src.model->links_.size() > kMaxUrdfLinks)
    throw InputError(path, 0, 0,
                     std::to_string(src.model->links_.size()) + " links: more than the " +
                         std::to_string(kMaxUrdfLinks) +
                         " a robot description may have here (symoroc models serial arms)");
  return src;
}

// The tip: --tip-link (below the base), else where the one path of moving joints ends.
urdf::LinkConstSharedPtr chain_tip(const UrdfSource& src, const urdf::LinkConstSharedPtr& base,
                                   const ModelingOptions& options) {
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
    tip = src.link(options.tip_link, "the tip link");
    urdf::LinkConstSharedPtr up = tip;
    while (up && up != base) up = up->getParent();
    if (!up)
      throw InputError(src.path, src.line_of("link", tip->name), 0,
                       "the tip link '" + tip->name + "' is not below the base link '" + base->name + "'");
    return tip;
  }
  tip = base;
  for (;;) {
    std::vector<urdf::LinkSharedPtr> next;
    for (std::size_t c = 0; c < tip->child_links.size(); ++c) {
      const auto& child = tip->child_links[c];
      if (moving(*child->parent_joint) || has_moving(*child)) next.push_back(child);
    }
    if (next.empty()) break;
    if (next.size() > 1)
      throw InputError(src.path, src.line_of("link", tip->name), 0,
                       "the link '" + tip->name + "' branches into moving joints ('" + next[0]->parent_joint->name +
                           "' and '" + next[1]->parent_joint->name + "'): name the chain's end with --tip-link");
    tip = next[0];
  }
  return tip;
}

// The chain's joints, base to tip: revolute, continuous or prismatic, independent, with an axis.
Chain find_chain(const UrdfSource& src, const ModelingOptions& options) {
  const std::string& path = src.path;
  Chain chain;
  chain.base = options.base_link.empty() ? src.model->getRoot() : src.link(options.base_link, "the base link");
  chain.tip = chain_tip(src, chain.base, options);
  std::vector<urdf::JointConstSharedPtr> path_joints;
  for (urdf::LinkConstSharedPtr l = chain.tip; l != chain.base; l = l->getParent())
    path_joints.insert(path_joints.begin(), l->parent_joint);
  for (const auto& j : path_joints) {
    const int line = src.line_of("joint", j->name);
    switch (j->type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
      case urdf::Joint::PRISMATIC:
        break;
      case urdf::Joint::FIXED:
        continue;
      default:
        throw InputError(path, line, 0,
                         "joint '" + j->name + "' on the chain is " +
                             (j->type == urdf::Joint::FLOATING ? "floating"
                              : j->type == urdf::Joint::PLANAR ? "planar"
                                                               : "of an unknown type") +
                             ": only revolute, continuous and prismatic joints are supported");
    }
    if (j->mimic)
      throw InputError(path, line, 0,
                       "joint '" + j->name + "' on the chain mimics '" + j->mimic->joint_name +
                           "': a chain joint must be independent");
    if (vec(j->axis).norm() < 1e-12) throw InputError(path, line, 0, "joint '" + j->name + "' has a zero axis");
    chain.joints.push_back(j);
    chain.names.insert(j->name);
  }
  const int n = static_cast<int>(chain.joints.size());
  const std::string between = "between '" + chain.base->name + "' and '" + chain.tip->name + "'";
  if (n == 0) throw InputError(path, 0, 0, "no moving joint " + between);
  if (n > kMaxChainJoints)
    throw InputError(path, src.line_of("joint", chain.joints[kMaxChainJoints]->name), 0,
                     std::to_string(n) + " moving joints " + between + ": symoroc models serial arms of at most " +
                         std::to_string(kMaxChainJoints));
  return chain;
}

// --lock: moving joints off the chain, each at a position within its limits.
void check_locks(const UrdfSource& src, const Chain& chain, const ModelingOptions& options) {
  for (const auto& [name, value] : options.locked) {
    const auto j = src.model->getJoint(name);
    if (!j || !moving(*j) || chain.names.count(name))
      throw InputError(src.path, j ? src.line_of("joint", name) : 0, 0,
                       "--lock " + name + ": not a moving joint off the chain");
    const std::string lock = "--lock " + name + "=" + number_text(value);
    if (!std::isfinite(value) || std::abs(value) > 1e3)
      throw InputError(src.path, src.line_of("joint", name), 0, lock + ": not a position");
    const bool bounded = j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::PRISMATIC;
    if (bounded && j->limits && j->limits->lower <= j->limits->upper &&
        (value < j->limits->lower || value > j->limits->upper))
      throw InputError(src.path, src.line_of("joint", name), 0,
                       lock + ": outside the joint's limits " + number_text(j->limits->lower) + " .. " +
                           number_text(j->limits->upper));
  }
}

LinkPlacement place_links(const UrdfSource& src, const Chain& chain, const ModelingOptions& options) {
  LinkPlacement out;
  auto& T = out.T;
  auto& body = out.body;
  const int n = static_cast<int>(chain.joints.size());
  std::function<void(const urdf::Link&)> walk = [&](const urdf::Link& l) {
    for (const auto& c : l.child_links) {
      const urdf::Joint& j = *c->parent_joint;
      Isometry3d motion = Isometry3d::Identity();
      int b = body[l.name];
      if (chain.names.count(j.name)) {
        for (int k = 0; k < n; ++k)
          if (chain.joints[k]->name == j.name) b = k + 1;
      } else if (moving(j)) {
        if (j.type != urdf::Joint::PRISMATIC && j.type != urdf::Joint::REVOLUTE && j.type != urdf::Joint::CONTINUOUS)
          throw InputError(src.path, src.line_of("joint", j.name), 0,
                           "joint '" + j.name + "' off the chain is floating or planar: it cannot be locked");
        const auto it = options.locked.find(j.name);
        const double q = it == options.locked.end() ? 0.0 : it->second;
        motion = urdf_geometry::motion(j, q);
        out.locked.push_back(j.name + " = " + number_text(q));
      }
      T[c->name] = T[l.name] * pose(j.parent_to_joint_origin_transform) * motion;
      body[c->name] = b;
      walk(*c);
    }
  };
  T[chain.base->name] = Isometry3d::Identity();
  body[chain.base->name] = 0;
  walk(*chain.base);
  return out;
}

// The point of line 1 closest to line 2 (on a parallel line 2: the foot of p2).
Vector3d closest_on(const Vector3d& p1, const Vector3d& d1, const Vector3d& p2, const Vector3d& d2) {
  const Vector3d w = p1 - p2;
  const double b = d1.dot(d2), den = 1 - b * b;
  if (den < 1e-12) return Vector3d(p1 + (p2 - p1).dot(d1) * d1);
  const double s = (b * d2.dot(w) - d1.dot(w)) / den;
  return Vector3d(p1 + s * d1);
}

DhChain dh_chain(const Chain& chain, const LinkPlacement& placed) {
  const auto& joints = chain.joints;
  const int n = static_cast<int>(joints.size());
  std::vector<Vector3d> P(n), u(n);
  for (int k = 0; k < n; ++k) {
    const Isometry3d& Tc = placed.T.at(joints[k]->child_link_name);
    P[k] = Tc.translation();
    u[k] = Tc.linear() * vec(joints[k]->axis).normalized();
  }
  DhChain out;
  std::vector<Dh>& dh = out.dh;
  dh.resize(n);
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
    O_prev = joints[0]->type == urdf::Joint::PRISMATIC || n == 1 ? P[0] : closest_on(P[0], u[0], P[1], u[1]);
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
    p.sigma = joints[k]->type == urdf::Joint::PRISMATIC ? 1 : 0;
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
      throw std::logic_error("symoroc model: the DH frame of joint '" + joints[k]->name +
                             "' does not reproduce its axis (an internal error)");
    R_prev = Tk.linear();
    O_prev = Tk.translation();
  }
  // Frames 1..n again, at q = 0, from the rounded parameters.
  std::vector<Isometry3d>& F = out.F;
  F.resize(n + 1);
  F[0] = frame0;
  for (int k = 0; k < n; ++k) F[k + 1] = F[k] * dh_transform(dh[k]);
  return out;
}

// Every URDF link's inertial summed into its chain link (body), about the DH frame's origin,
// in the DH frame: the links without one and those whose inertial is not physically consistent
// are said in `notes`.
std::vector<Body> chain_bodies(const UrdfSource& src, const LinkPlacement& placed, const DhChain& frames,
                               std::vector<std::string>& notes) {
  const std::vector<Isometry3d>& F = frames.F;
  const int n = static_cast<int>(frames.dh.size());
  std::vector<Body> bodies(n + 1);
  std::vector<std::string> massless, inconsistent;
  for (const auto& [name, Tl] : placed.T) {
    const int b = placed.body.at(name);
    bodies[b].links.push_back(name);
    const auto l = src.model->getLink(name);
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
    const Isometry3d Tc = Tl * pose(I.origin);   // the inertial frame in base coordinates
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
    notes.push_back(s);
  }
  for (const auto& name : inconsistent)
    notes.push_back(
        "warning: the inertial of link '" + name + "' (line " + std::to_string(src.line_of("link", name)) +
        ") is not physically consistent (a negative mass or principal moment, or the triangle inequality broken)");
  return bodies;
}

}  // namespace

UrdfChain read_urdf_chain(const std::string& path, const ModelingOptions& options) {
  const UrdfSource src = read_urdf_source(path);
  const Chain chain = find_chain(src, options);
  check_locks(src, chain, options);
  UrdfChain out;
  const LinkPlacement placed = place_links(src, chain, options);
  if (!placed.locked.empty()) {
    std::string s = "off-chain moving joints locked (merged into the link they hang from):";
    for (const auto& l : placed.locked) s += " " + l;
    out.notes.push_back(s);
  }
  const DhChain frames = dh_chain(chain, placed);
  const std::vector<Body> bodies = chain_bodies(src, placed, frames, out.notes);
  const std::string given_name = options.name.empty() ? src.model->getName() : options.name;
  out.name = identifier(given_name);
  if (out.name != given_name)
    out.notes.push_back("warning: the robot's name '" + given_name + "' is no C++ identifier: written as '" + out.name +
                        "'");
  out.par_text = par_text(out.name, path, chain, frames, options);
  out.robot_yaml = robot_yaml_text(out.name, src, chain, placed, frames, bodies, options, out.notes);
  return out;
}

}  // namespace symoro::codegen::modeling
