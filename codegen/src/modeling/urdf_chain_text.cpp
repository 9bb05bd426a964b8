// A URDF's serial chain as .par and robot.yaml text (urdf_chain_parts.hpp).
#include <cmath>
#include <functional>

#include "equation_text.hpp"
#include "symoro/urdf_geometry.hpp"
#include "urdf_chain_parts.hpp"

namespace symoro::codegen::modeling::urdf_parts {

namespace {

using urdf_geometry::exact;
using urdf_geometry::kAngleSnap;

// An angle as .par text: exact multiples of pi/2 by name.
std::string angle_text(double a) {
  const double k = std::round(a / (M_PI / 2));
  if (std::abs(a - k * M_PI / 2) <= kAngleSnap) {
    const int q = static_cast<int>(k);
    switch (q) {
      case 0:
        return "0";
      case 1:
        return "pi/2";
      case -1:
        return "-pi/2";
      case 2:
        return "pi";
      case -2:
        return "-pi";
    }
  }
  return number_text(a);
}

// A pose as robot.yaml writes it: xyz and URDF's roll, pitch, yaw.
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
  return "{xyz: [" + n(p.x()) + ", " + n(p.y()) + ", " + n(p.z()) + "], rpy: [" + n(roll) + ", " + n(pitch) + ", " +
         n(yaw) + "]}";
}

}  // namespace

std::string identifier(const std::string& s) {
  std::string out;
  for (const char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "_" + out;
  return out;
}

std::string par_text(const std::string& name, const std::string& path, const Chain& chain, const DhChain& frames,
                     const ModelingOptions& options) {
  const std::vector<Dh>& dh = frames.dh;
  const int n = static_cast<int>(dh.size());
  auto column = [&](auto get) {
    std::string s = "{";
    for (int k = 0; k < n; ++k) s += (k ? "," : "") + get(k);
    return s + "}";
  };
  auto named = [&](const std::string& fam, bool on) {
    return column([&](int k) { return on ? fam + std::to_string(k + 1) : std::string("0"); });
  };
  const Vector3d g0 = frames.F[0].linear().transpose() * Vector3d(0, 0, -1);
  auto gravity = [&](double v) {
    v = exact(v);
    if (std::abs(v) < 1e-15) return std::string("0");
    if (v == 1) return std::string("G3");
    if (v == -1) return std::string("-G3");
    return number_text(v) + "*G3";
  };
  std::string par = "(* Robotname = '" + name + "' *)\n";
  par += "(* Written by symoroc model from " + path + ", base link " + chain.base->name + ", tip link " +
         chain.tip->name + " *)\n";
  par += "NL = " + std::to_string(n) + "\nNJ = " + std::to_string(n) + "\nNF = " + std::to_string(n) +
         "\nType = 0\nis_floating = False\nis_mobile = False\n\n(* Geometric parameters *)\n";
  par += "ant = " + column([&](int k) { return std::to_string(k); }) + "\n";
  par += "sigma = " + column([&](int k) { return std::to_string(dh[k].sigma); }) + "\n";
  par += "b = " + column([&](int k) { return number_text(dh[k].b); }) + "\n";
  par += "d = " + column([&](int k) { return number_text(dh[k].d); }) + "\n";
  par +=
      "r = " + column([&](int k) { return dh[k].sigma ? "r" + std::to_string(k + 1) : number_text(dh[k].r); }) + "\n";
  par += "gamma = " + column([&](int k) { return angle_text(dh[k].gamma); }) + "\n";
  par += "alpha = " + column([&](int k) { return angle_text(dh[k].alpha); }) + "\n";
  par += "mu = " + column([&](int) { return std::string("1"); }) + "\n";
  par +=
      "theta = " + column([&](int k) { return dh[k].sigma ? angle_text(dh[k].theta) : "th" + std::to_string(k + 1); }) +
      "\n";
  par += "\n(* Dynamic parameters and external forces *)\n";
  for (const char* fam : {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"})
    par += std::string(fam) + " = " + named(fam, true) + "\n";
  par += "IA = " + named("IA", options.rotor_inertia) + "\nFV = " + named("FV", options.viscous) +
         "\nFS = " + named("FS", options.coulomb) + "\n";
  for (const char* f : {"FX", "FY", "FZ", "CX", "CY", "CZ"}) par += std::string(f) + " = " + named("", false) + "\n";
  par += "\n(* Joint parameters *)\neta = " + named("", false) + "\nk = " + named("", false) + "\n";
  par += "QP = " + named("QP", true) + "\nQDP = " + named("QDP", true) + "\nGAM = " + named("GAM", true) + "\n";
  par += "\n(* Velocity and acceleration of the base *)\nW0 = {0,0,0}\nWP0 = {0,0,0}\nV0 = {0,0,0}\nVP0 = {0,0,0}\n";
  par += "\n(* Acceleration of gravity: -z of the URDF's base link, in frame 0 *)\nG = {" + gravity(g0.x()) + "," +
         gravity(g0.y()) + "," + gravity(g0.z()) + "}\n";
  par +=
      "\n(* Transformation of 0 frame position fT0 *)\nZ = {1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1}\n\n(* End of definition "
      "*)\n";
  return par;
}

std::string robot_yaml_text(const std::string& name, const UrdfSource& src, const Chain& chain,
                            const LinkPlacement& placed, const DhChain& frames, const std::vector<Body>& bodies,
                            const ModelingOptions& options, std::vector<std::string>& notes) {
  const std::string& path = src.path;
  const urdf::LinkConstSharedPtr &base = chain.base, &tip = chain.tip;
  const std::vector<Isometry3d>& F = frames.F;
  const int n = static_cast<int>(chain.joints.size());
  std::string y =
      "# " + name + ": written by symoroc model from " + path + " (base link " + base->name + ", tip link " +
      tip->name +
      ").\n# Review the joint limits; the nominal parameters are the URDF's inertials in the model's frames.\n";
  y += "description: " + src.model->getName() + " from its URDF\n\nconstants:\n  G3: 9.81        # m/s^2\n\njoints:\n";
  bool prismatic = false;
  for (int k = 0; k < n; ++k) {
    const urdf::Joint& j = *chain.joints[k];
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
      notes.push_back("warning: joint '" + j.name + "' (line " + std::to_string(src.line_of("joint", j.name)) +
                      ") has empty limits (" + number_text(lower) + " .. " + number_text(upper) +
                      "): robot.yaml gets -pi .. pi");
      lower = -M_PI;
      upper = M_PI;
    }
    if (identifier(j.name) != j.name)
      notes.push_back("warning: joint '" + j.name + "' (line " + std::to_string(src.line_of("joint", j.name)) +
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
    y += "  XX" + s + ": " + v(B.J(0, 0)) + "\n  XY" + s + ": " + v(B.J(0, 1)) + "\n  XZ" + s + ": " + v(B.J(0, 2)) +
         "\n  YY" + s + ": " + v(B.J(1, 1)) + "\n  YZ" + s + ": " + v(B.J(1, 2)) + "\n  ZZ" + s + ": " + v(B.J(2, 2)) +
         "\n  MX" + s + ": " + v(B.ms.x()) + "\n  MY" + s + ": " + v(B.ms.y()) + "\n  MZ" + s + ": " + v(B.ms.z()) +
         "\n  M" + s + ": " + v(B.m) + "\n";
    const auto& dyn = chain.joints[k - 1]->dynamics;
    if (options.rotor_inertia) y += "  IA" + s + ": 0\n";
    if (options.viscous) y += "  FV" + s + ": " + v(dyn ? dyn->damping : 0.0) + "\n";
    if (options.coulomb) y += "  FS" + s + ": " + v(dyn ? dyn->friction : 0.0) + "\n";
  }
  y += "\n# Where the model's frames are in the URDF, and which URDF links each model link merges.\nurdf:\n";
  y += "  file: " +
       std::string(path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1)) + "\n";
  y += "  base_link: " + base->name + "\n  tip_link: " + tip->name + "\n";
  y += "  frame0_in_base: " + xyz_rpy(F[0]) + "\n";
  y += "  tip_in_last_frame: " + xyz_rpy(F[n].inverse() * placed.T.at(tip->name)) + "\n";
  y += "  joints: [";
  for (int k = 0; k < n; ++k) y += (k ? ", " : "") + chain.joints[k]->name;
  y += "]\n  links:\n";
  for (int k = 1; k <= n; ++k) {
    y += "    - [";
    for (std::size_t i = 0; i < bodies[k].links.size(); ++i) y += (i ? ", " : "") + bodies[k].links[i];
    y += "]\n";
  }
  if (!options.locked.empty() || !placed.locked.empty()) {
    y += "  locked: {";
    bool first = true;
    std::function<void(const urdf::Link&)> list_locked = [&](const urdf::Link& l) {
      for (const auto& c : l.child_links) {
        const urdf::Joint& j = *c->parent_joint;
        if (moving(j) && !chain.names.count(j.name)) {
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
  return y;
}

}  // namespace symoro::codegen::modeling::urdf_parts
