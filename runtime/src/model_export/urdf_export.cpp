#include "symoro/model_export/urdf_export.hpp"

#include <cmath>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "export_text.hpp"
#include "symoro/mdh.hpp"

namespace symoro::model_export {

namespace {

using detail::comment_text;
using detail::joint_of_frame;
using detail::num;
using detail::xml_escaped;

int slot_of(const std::string& family) {
  static const char* order[10] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"};
  for (int i = 0; i < 10; ++i)
    if (family == order[i]) return i;
  return -1;
}

}  // namespace

namespace detail {

void check_description(const UrdfDescription& d) {
  if (d.s.size() != static_cast<Eigen::Index>(d.names.size()))
    throw std::invalid_argument(
        fmt::format("urdf export: {} standard parameters for {} names", d.s.size(), d.names.size()));
  if (!d.s.allFinite()) throw std::invalid_argument("urdf export: a standard parameter is not finite");
  std::size_t movable = 0;
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    const auto& f = d.frames[i];
    if (f.ant < 0 || f.ant > static_cast<int>(i))
      throw std::invalid_argument(fmt::format("urdf export: frame {} has antecedent {}", i + 1, f.ant));
    if (f.sigma != 2) ++movable;
  }
  if (movable != d.joints.size())
    throw std::invalid_argument(fmt::format("urdf export: {} movable frames for {} joints", movable, d.joints.size()));
}

}  // namespace detail

UrdfInertial inertial_about_com(const Eigen::Matrix3d& inertia_origin, const Eigen::Vector3d& first_moment,
                                double mass) {
  UrdfInertial u;
  u.present = mass != 0 || !first_moment.isZero(0) || !inertia_origin.isZero(0);
  u.mass = mass;
  u.com = mass != 0 ? Eigen::Vector3d(first_moment / mass) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d& c = u.com;
  u.inertia = inertia_origin - mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  u.inertia = 0.5 * (u.inertia + u.inertia.transpose()).eval();
  return u;
}

void inertial_about_origin(const UrdfInertial& in, Eigen::Matrix3d& inertia_origin, Eigen::Vector3d& first_moment,
                           double& mass) {
  const Eigen::Vector3d& c = in.com;
  mass = in.mass;
  first_moment = in.mass * c;
  inertia_origin = in.inertia + in.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
}

UrdfInertial link_inertial(const UrdfDescription& d, int frame) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  double m = 0;
  static const int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
  for (std::size_t k = 0; k < d.names.size(); ++k) {
    if (d.names[k].joint != frame) continue;
    const int slot = slot_of(d.names[k].family);
    const double v = d.s(static_cast<Eigen::Index>(k));
    if (slot >= 0 && slot < 6)
      I(row[slot], col[slot]) = I(col[slot], row[slot]) = v;
    else if (slot >= 6 && slot < 9)
      h(slot - 6) = v;
    else if (slot == 9)
      m = v;
  }
  return inertial_about_com(I, h, m);
}

std::string urdf_link_name(const UrdfDescription& d, int frame) {
  if (frame == 0) return "base_link";
  const int j = joint_of_frame(d, frame);
  return j >= 0 ? std::string(d.joints[static_cast<std::size_t>(j)].name) + "_link"
                : fmt::format("frame{}_link", frame);
}

std::string urdf_joint_name(const UrdfDescription& d, int frame) {
  const int j = joint_of_frame(d, frame);
  return j >= 0 ? std::string(d.joints[static_cast<std::size_t>(j)].name) : fmt::format("frame{}_fixed", frame);
}

Eigen::Vector3d urdf_rpy(const Eigen::Matrix3d& R) {
  const double cp = std::hypot(R(0, 0), R(1, 0));
  if (cp > 1e-12) return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), cp), std::atan2(R(1, 0), R(0, 0))};
  // Pitch +-pi/2: only roll - yaw (or roll + yaw) is defined; yaw = 0.
  if (R(2, 0) < 0) return {std::atan2(R(0, 1), R(1, 1)), M_PI / 2, 0.0};
  return {std::atan2(-R(0, 1), R(1, 1)), -M_PI / 2, 0.0};
}

std::string standard_unit(const std::string& family, bool prismatic) {
  const int slot = slot_of(family);
  if (slot >= 0 && slot < 6) return "kg*m^2";
  if (slot >= 6 && slot < 9) return "kg*m";
  if (slot == 9) return "kg";
  if (family == "IA") return prismatic ? "kg" : "kg*m^2";
  if (family == "FV") return prismatic ? "N*s/m" : "N*m*s/rad";
  if (family == "FS") return prismatic ? "N" : "N*m";
  return "";
}

std::string urdf_text(const UrdfDescription& d) {
  detail::check_description(d);
  const int nf = static_cast<int>(d.frames.size());
  std::set<std::string> links, joints;
  for (int f = 0; f <= nf; ++f)
    if (!links.insert(urdf_link_name(d, f)).second)
      throw std::invalid_argument("urdf export: two links named " + urdf_link_name(d, f));
  for (int f = 1; f <= nf; ++f)
    if (!joints.insert(urdf_joint_name(d, f)).second)
      throw std::invalid_argument("urdf export: two joints named " + urdf_joint_name(d, f));
  const auto value_of = [&](const char* family, int frame, bool& found) {
    return detail::frame_value(d, family, frame, found);
  };

  std::string x = "<?xml version=\"1.0\"?>\n";
  x += "<!-- " + comment_text(d.robot) +
       ": written by symoro (dynid export, URDF output).\n"
       "  Link frames: every link frame is the model's modified Denavit-Hartenberg frame (Khalil-Kleinfinger)\n"
       "  of the same number, frame 0 = base_link: the frame j relative to its antecedent a(j) is\n"
       "    Rot(z, gamma_j) Trans(z, b_j) Rot(x, alpha_j) Trans(x, d_j) Rot(z, theta_j) Trans(z, r_j),\n"
       "  with the joint variable added to theta_j (revolute) or r_j (prismatic). Each joint's origin is that\n"
       "  transform at q = 0 and its axis is z of the child frame, so the URDF joint position equals the\n"
       "  model's q (no offset, no sign change).\n"
       "  Inertials: mass M_j, CoM (MX_j, MY_j, MZ_j) / M_j and the inertia about the CoM, all in link frame j\n"
       "  (rpy 0), from the standard parameters XX_j..ZZ_j (about the frame origin), MX_j MY_j MZ_j, M_j.\n"
       "  A link without inertial parameters (or all 0) has no <inertial>.\n"
       "  Joint dynamics: damping = FV_j (viscous friction), friction = FS_j (Coulomb friction).\n"
       "  Rotor inertia IA_j (reflected motor inertia on joint j) has no URDF field: it is NOT in this file;\n"
       "  see the standard-parameter YAML/CSV written next to it. Numbers read back as the exact doubles. -->\n";
  for (const auto& n : d.notes) x += "<!-- " + comment_text(n) + " -->\n";
  x += "<robot name=\"" + xml_escaped(d.robot) + "\">\n";
  x += "  <link name=\"base_link\"/>\n";
  for (int f = 1; f <= nf; ++f) {
    const FrameInfo& fr = d.frames[static_cast<std::size_t>(f - 1)];
    const std::string link = urdf_link_name(d, f);
    const UrdfInertial in = link_inertial(d, f);
    if (!in.present) {
      x += "  <!-- frame " + std::to_string(f) + ": no inertial parameters (massless) -->\n";
      x += "  <link name=\"" + xml_escaped(link) + "\"/>\n";
    } else {
      x += "  <link name=\"" + xml_escaped(link) + "\">\n";
      x += "    <!-- frame " + std::to_string(f) + " -->\n    <inertial>\n";
      x += fmt::format("      <origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/>\n", num(in.com.x()), num(in.com.y()),
                       num(in.com.z()));
      x += "      <mass value=\"" + num(in.mass) + "\"/>\n";
      x += fmt::format("      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n",
                       num(in.inertia(0, 0)), num(in.inertia(0, 1)), num(in.inertia(0, 2)), num(in.inertia(1, 1)),
                       num(in.inertia(1, 2)), num(in.inertia(2, 2)));
      x += "    </inertial>\n  </link>\n";
    }
    const Eigen::Isometry3d T = mdh_transform(fr, 0.0);
    const Eigen::Vector3d p = T.translation(), rpy = urdf_rpy(T.linear());
    const int j = joint_of_frame(d, f);
    const char* type = fr.sigma == 2 ? "fixed" : fr.sigma == 1 ? "prismatic" : "revolute";
    x += "  <joint name=\"" + xml_escaped(urdf_joint_name(d, f)) + "\" type=\"" + type + "\">\n";
    x += fmt::format("    <!-- frame {}: gamma {} b {} alpha {} d {} theta {} r {} -->\n", f, num(fr.gamma), num(fr.b),
                     num(fr.alpha), num(fr.d), num(fr.theta), num(fr.r));
    x += "    <parent link=\"" + xml_escaped(urdf_link_name(d, fr.ant)) + "\"/>\n";
    x += "    <child link=\"" + xml_escaped(link) + "\"/>\n";
    x += fmt::format("    <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>\n", num(p.x()), num(p.y()), num(p.z()),
                     num(rpy(0)), num(rpy(1)), num(rpy(2)));
    if (j >= 0) {
      const JointInfo& ji = d.joints[static_cast<std::size_t>(j)];
      x += "    <axis xyz=\"0 0 1\"/>\n";
      x += fmt::format("    <limit lower=\"{}\" upper=\"{}\" effort=\"{}\" velocity=\"{}\"/>\n", num(ji.lower),
                       num(ji.upper), num(ji.effort), num(ji.velocity));
      bool has_fv = false, has_fs = false, has_ia = false;
      const double fv = value_of("FV", f, has_fv), fs = value_of("FS", f, has_fs), ia = value_of("IA", f, has_ia);
      if (has_fv || has_fs) x += fmt::format("    <dynamics damping=\"{}\" friction=\"{}\"/>\n", num(fv), num(fs));
      if (has_ia)
        x += "    <!-- rotor inertia IA" + std::to_string(f) + " = " + num(ia) + " " +
             standard_unit("IA", fr.sigma == 1) + " (no URDF field; not applied by URDF consumers) -->\n";
    }
    x += "  </joint>\n";
  }
  x += "</robot>\n";
  return x;
}

std::string standard_parameters_yaml(const UrdfDescription& d, const std::string& header) {
  detail::check_description(d);
  std::string y = header;
  if (!y.empty() && y.back() != '\n') y += '\n';
  y += "# Frame-origin standard parameters (modified-DH link frames): XX..ZZ about the frame origin, MX MY MZ = M * "
       "CoM,\n"
       "# M, IA (rotor inertia: not representable in URDF, only here), FV (URDF damping), FS (URDF friction).\n";
  y += d.names.empty() ? "parameters: []\n" : "parameters:\n";
  for (std::size_t k = 0; k < d.names.size(); ++k) {
    const auto& p = d.names[k];
    const bool prismatic = p.joint >= 1 && p.joint <= static_cast<int>(d.frames.size()) &&
                           d.frames[static_cast<std::size_t>(p.joint - 1)].sigma == 1;
    y += fmt::format("  - {{name: \"{}\", frame: {}, family: \"{}\", unit: \"{}\", value: {}}}\n", p.name, p.joint,
                     p.family, standard_unit(p.family, prismatic), num(d.s(static_cast<Eigen::Index>(k))));
  }
  return y;
}

std::string standard_parameters_csv(const UrdfDescription& d) {
  detail::check_description(d);
  std::string c = "name,frame,family,unit,value\n";
  for (std::size_t k = 0; k < d.names.size(); ++k) {
    const auto& p = d.names[k];
    const bool prismatic = p.joint >= 1 && p.joint <= static_cast<int>(d.frames.size()) &&
                           d.frames[static_cast<std::size_t>(p.joint - 1)].sigma == 1;
    c += fmt::format("{},{},{},{},{}\n", p.name, p.joint, p.family, standard_unit(p.family, prismatic),
                     num(d.s(static_cast<Eigen::Index>(k))));
  }
  return c;
}

}  // namespace symoro::model_export
