// MJCF of a model and its standard parameters (symoro/model_export/mjcf_export.hpp).
#include "symoro/model_export/mjcf_export.hpp"

#include <cmath>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "export_text.hpp"
#include "symoro/mdh.hpp"

namespace symoro::model_export {

namespace {

using detail::comment_text;
using detail::joint_of_frame;
using detail::num;
using detail::xml_escaped;

std::string vec(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

std::string quat_text(const Eigen::Matrix3d& R) {
  const Eigen::Vector4d q = mjcf_quat(R);
  return num(q(0)) + " " + num(q(1)) + " " + num(q(2)) + " " + num(q(3));
}

// <inertial> in principal axes (quat, diaginertia), diagonalized here to the last bits: MuJoCo's
// own diagonalization of a fullinertia stops at an absolute tolerance (1e-12 kg m^2), 1e-8 of
// the torque on a light link.
std::string inertial_text(const UrdfInertial& in, const std::string& indent) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(in.inertia);
  Eigen::Matrix3d R = eig.eigenvectors();
  if (R.determinant() < 0) R.col(2) *= -1;
  const Eigen::Vector3d p = eig.eigenvalues().cwiseMax(0.0);
  return fmt::format("{}<inertial pos=\"{}\" quat=\"{}\" mass=\"{}\" diaginertia=\"{}\"/>\n", indent, vec(in.com),
                     quat_text(R), num(in.mass), vec(p));
}

// A movable body with no mass below it, which MuJoCo refuses (CRANE-X7's hand axis): a point of
// 1e-12 kg with 1e-14 kg m^2 at its origin, above MuJoCo's mjMINVAL (1e-15), 1e-11 N m at most.
constexpr const char* kTokenInertial = "<inertial pos=\"0 0 0\" mass=\"1e-12\" diaginertia=\"1e-14 1e-14 1e-14\"/>";

// What MuJoCo's compiler checks of a body's inertia (its principal moments A, B, C: each >= 0 and
// A + B >= C), said for the frame rather than left to MuJoCo's message.
void check_inertial(const UrdfInertial& in, const std::string& what) {
  if (!(in.mass >= 0)) throw std::invalid_argument(fmt::format("mjcf export: {} has mass {}", what, in.mass));
  const Eigen::Vector3d p = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(in.inertia).eigenvalues();
  const double tol = 1e-12 * std::max(1.0, p.cwiseAbs().maxCoeff());
  if (p(0) < -tol || p(0) + p(1) < p(2) - tol)
    throw std::invalid_argument(
        fmt::format("mjcf export: {}'s principal moments of inertia {} {} {} are no body's (each >= 0, the two smaller "
                    "summing to at least the largest): export the physically consistent parameters",
                    what, p(0), p(1), p(2)));
}

class Writer {
 public:
  Writer(const UrdfDescription& d, const std::vector<MjcfAttachment>& a) : d_(d), attachments_(a) {}

  // Frame f's body and, inside it, the bodies of the frames whose antecedent it is.
  void body(int f, const std::string& indent) {
    const FrameInfo& fr = d_.frames[static_cast<std::size_t>(f - 1)];
    const Eigen::Isometry3d T = mdh_transform(fr, 0.0);
    const std::string link = urdf_link_name(d_, f);
    x += fmt::format("{}<body name=\"{}\" pos=\"{}\" quat=\"{}\">\n", indent, xml_escaped(link), vec(T.translation()),
                     quat_text(T.linear()));
    const std::string in = indent + "  ";
    x += fmt::format("{}<!-- frame {}: gamma {} b {} alpha {} d {} theta {} r {} -->\n", in, f, num(fr.gamma),
                     num(fr.b), num(fr.alpha), num(fr.d), num(fr.theta), num(fr.r));
    const UrdfInertial inertial = link_inertial(d_, f);
    if (inertial.present) {
      check_inertial(inertial, fmt::format("frame {} ({})", f, link));
      x += inertial_text(inertial, in);
    } else if (fr.sigma != 2 && !massive_below(f)) {
      x += in + "<!-- no inertial parameters: massless; a token inertial, which MuJoCo needs on a moving body -->\n";
      x += in + kTokenInertial + "\n";
    } else {
      x += in + "<!-- no inertial parameters: massless -->\n";
    }
    if (const int j = joint_of_frame(d_, f); j >= 0) joint(f, j, in);
    for (const MjcfAttachment& a : attachments_)
      if (a.frame == f) attachment(a, in);
    for (int g = f + 1; g <= static_cast<int>(d_.frames.size()); ++g)
      if (d_.frames[static_cast<std::size_t>(g - 1)].ant == f) body(g, in);
    x += indent + "</body>\n";
  }

  // The top-level bodies: frames on frame 0.
  void roots(const std::string& indent) {
    for (const MjcfAttachment& a : attachments_)
      if (a.frame == 0) attachment(a, indent);
    for (int g = 1; g <= static_cast<int>(d_.frames.size()); ++g)
      if (d_.frames[static_cast<std::size_t>(g - 1)].ant == 0) body(g, indent);
  }

  std::string x;
  std::vector<std::string> motors;

 private:
  // Whether a frame after f on f's subtree has mass (or a payload rides below f).
  bool massive_below(int f) const {
    for (const MjcfAttachment& a : attachments_)
      if (a.frame == f && a.inertial.mass > 0) return true;
    for (int g = f + 1; g <= static_cast<int>(d_.frames.size()); ++g)
      if (d_.frames[static_cast<std::size_t>(g - 1)].ant == f && (link_inertial(d_, g).mass > 0 || massive_below(g)))
        return true;
    return false;
  }

  void joint(int f, int j, const std::string& in) {
    const JointInfo& ji = d_.joints[static_cast<std::size_t>(j)];
    const bool prismatic = d_.frames[static_cast<std::size_t>(f - 1)].sigma == 1;
    bool has_ia = false, has_fv = false, has_fs = false;
    double ia = detail::frame_value(d_, "IA", f, has_ia), fv = detail::frame_value(d_, "FV", f, has_fv),
           fs = detail::frame_value(d_, "FS", f, has_fs);
    // Rounding's negatives (IA of a joint whose rotor inertia regroups into a link: -1e-17) are 0;
    // a negative that is not rounding is no simulator's.
    for (auto [value, family] : {std::pair<const double*, const char*>{&ia, "IA"}, {&fv, "FV"}, {&fs, "FS"}})
      if (*value < -1e-12)
        throw std::invalid_argument(fmt::format("mjcf export: {}{} = {} is negative", family, f, *value));
    const auto clamp = [](double v) { return std::max(v, 0.0); };
    std::string extra;
    if (has_ia) extra += " armature=\"" + num(clamp(ia)) + "\"";
    if (has_fv) extra += " damping=\"" + num(clamp(fv)) + "\"";
    if (has_fs) extra += " frictionloss=\"" + num(clamp(fs)) + "\"";
    x += fmt::format(
        "{}<joint name=\"{}\" type=\"{}\" pos=\"0 0 0\" axis=\"0 0 1\" limited=\"true\" "
        "range=\"{} {}\"{}/>\n",
        in, xml_escaped(ji.name), prismatic ? "slide" : "hinge", num(ji.lower), num(ji.upper), extra);
    motors.push_back(
        fmt::format("<motor name=\"{0}\" joint=\"{0}\" gear=\"1\" ctrllimited=\"true\" "
                    "ctrlrange=\"{1} {2}\" forcelimited=\"true\" forcerange=\"{1} {2}\"/>",
                    xml_escaped(ji.name), num(-ji.effort), num(ji.effort)));
  }

  void attachment(const MjcfAttachment& a, const std::string& in) {
    check_inertial(a.inertial, a.name);
    x += fmt::format("{}<body name=\"{}\" pos=\"{}\" quat=\"{}\">\n", in, xml_escaped(a.name),
                     vec(a.pose.translation()), quat_text(a.pose.linear()));
    x += inertial_text(a.inertial, in + "  ");
    x += in + "</body>\n";
  }

  const UrdfDescription& d_;
  const std::vector<MjcfAttachment>& attachments_;
};

}  // namespace

Eigen::Vector4d mjcf_quat(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;  // one of the two signs, for diffable output
  return {q.w(), q.x(), q.y(), q.z()};
}

std::string mjcf_text(const UrdfDescription& d, const Eigen::Vector3d& gravity,
                      const std::vector<MjcfAttachment>& attachments) {
  detail::check_description(d);
  std::set<std::string> names;
  for (int f = 1; f <= static_cast<int>(d.frames.size()); ++f)
    if (!names.insert(urdf_link_name(d, f)).second)
      throw std::invalid_argument("mjcf export: two bodies named " + urdf_link_name(d, f));
  for (const MjcfAttachment& a : attachments) {
    if (a.frame < 0 || a.frame > static_cast<int>(d.frames.size()))
      throw std::invalid_argument(fmt::format("mjcf export: {} on frame {}, which the model has not", a.name, a.frame));
    if (!names.insert(a.name).second) throw std::invalid_argument("mjcf export: two bodies named " + a.name);
  }
  Writer w(d, attachments);
  w.roots("    ");
  std::string x = "<!-- " + comment_text(d.robot) +
                  ": written by symoro (dynid export, MJCF output).\n"
                  "  Bodies: every body frame is the model's modified Denavit-Hartenberg frame (Khalil-Kleinfinger)\n"
                  "  of the same number, frame 0 = the world: pos and quat (w x y z) are the frame's transform from\n"
                  "  its antecedent at q = 0, and each joint turns (slides) about z at the body's origin, so MuJoCo's\n"
                  "  qpos equals the model's q (no offset, no sign change).\n"
                  "  Inertials: mass M_j, CoM (MX_j, MY_j, MZ_j) / M_j and the full inertia about the CoM in body\n"
                  "  frame j, from the standard parameters XX_j..ZZ_j (about the frame origin), MX_j MY_j MZ_j, M_j.\n"
                  "  Joints: armature = IA_j (rotor inertia), damping = FV_j (viscous friction), frictionloss = FS_j\n"
                  "  (Coulomb friction; MuJoCo solves it as a constraint), range = the joint limits. Motors: one per\n"
                  "  joint, gear 1, force limited to the joint's effort limit. Gravity: the model's, in frame 0.\n"
                  "  Numbers read back as the exact doubles. -->\n";
  for (const auto& n : d.notes) x += "<!-- " + comment_text(n) + " -->\n";
  x += "<mujoco model=\"" + xml_escaped(d.robot) + "\">\n";
  x += "  <compiler angle=\"radian\"/>\n";
  x += "  <option gravity=\"" + vec(gravity) + "\"/>\n";
  x += "  <worldbody>\n" + w.x + "  </worldbody>\n";
  if (!w.motors.empty()) {
    x += "  <actuator>\n";
    for (const std::string& m : w.motors) x += "    " + m + "\n";
    x += "  </actuator>\n";
  }
  x += "</mujoco>\n";
  return x;
}

}  // namespace symoro::model_export
