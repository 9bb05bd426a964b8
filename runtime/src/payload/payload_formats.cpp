#include "symoro/payload/payload_formats.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "symoro/io/yaml_numbers.hpp"

namespace symoro::payload {

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

std::string num(double v) { return io::number_text(v); }

std::string list(std::initializer_list<double> v) {
  std::string out = "[";
  for (double x : v) out += (out.size() > 1 ? ", " : "") + num(x);
  return out + "]";
}

std::string list(const Eigen::VectorXd& v) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) out += (i ? ", " : "") + num(v(i));
  return out + "]";
}

std::string six(const Eigen::Matrix3d& I) { return list({I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)}); }

Eigen::Vector3d rpy_of(const Eigen::Matrix3d& R) {  // R = Rz(yaw) Ry(pitch) Rx(roll)
  // + 0.0: no "-0" in the file.
  return {std::atan2(R(2, 1), R(2, 2)) + 0.0, std::asin(std::clamp(-R(2, 0), -1.0, 1.0)) + 0.0,
          std::atan2(R(1, 0), R(0, 0)) + 0.0};
}

// A pose {xyz, rpy} (rpy: R = Rz(yaw) Ry(pitch) Rx(roll), as URDF and robot.yaml write it).
Eigen::Isometry3d pose_at(const YAML::Node& n, const std::string& file, const std::string& what) {
  const Eigen::VectorXd xyz = io::yaml_numbers(n["xyz"], 3, file, what + " xyz");
  const Eigen::VectorXd rpy = io::yaml_numbers(n["rpy"], 3, file, what + " rpy");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      (Eigen::AngleAxisd(rpy(2), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy(1), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(rpy(0), Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  T.translation() = xyz;
  return T;
}

}  // namespace

std::string robot_flange(const std::string& robot_yaml, int link, int frames, Eigen::Isometry3d& flange_in_link) {
  flange_in_link = Eigen::Isometry3d::Identity();
  const YAML::Node root = io::load_yaml_file(robot_yaml);
  const YAML::Node u = root.IsMap() ? root["urdf"] : YAML::Node();
  if (!u || !u.IsMap() || !u["tip_link"] || !u["tip_in_last_frame"] || link != frames)
    return fmt::format("frame {}", link);
  flange_in_link = pose_at(u["tip_in_last_frame"], robot_yaml, "urdf.tip_in_last_frame");
  return u["tip_link"].as<std::string>();
}

std::string payload_yaml(const PayloadEstimate& e, const PayloadFileContext& c) {
  const PayloadInertial& p = e.payload;
  const Eigen::Vector3d rpy = rpy_of(c.flange_in_link.linear());
  std::string y;
  y += fmt::format("# dynid payload: a payload's inertial parameters on {} ({} model, arm parameters {}),\n", c.robot,
                   c.model, c.params);
  y += fmt::format("# identified from {}. docs/payload.md gives the conventions.\n", c.logs);
  y += "format: symoro-payload 1\n";
  y += fmt::format("robot: {}\n", c.robot);
  y += fmt::format("flange: {}  # the frame of everything below but `standard`\n", c.flange);
  y += fmt::format("flange_in_link: {{link: {}, xyz: {}, rpy: {}}}  # m, rad: the flange in the model's frame\n",
                   e.link, list(Eigen::VectorXd(c.flange_in_link.translation())), list(Eigen::VectorXd(rpy)));
  y += "payload:\n";
  y += fmt::format("  mass: {}  # kg{}\n", num(p.mass), e.known_mass ? " (given)" : "");
  y += fmt::format("  com: {}  # m, in the flange frame\n", list(Eigen::VectorXd(p.com)));
  y += fmt::format("  inertia: {}  # kg m^2 about the CoM, flange axes: ixx iyy izz ixy ixz iyz (tensor entries)\n",
                   six(p.inertia));
  y += "std_dev:  # one standard deviation, the residual's autocorrelation counted\n";
  y += fmt::format("  mass: {}\n", num(e.mass_std));
  y += fmt::format("  com: {}\n", list(Eigen::VectorXd(e.com_std)));
  y += fmt::format("  inertia: {}\n", list(Eigen::VectorXd(e.inertia_std)));
  y += fmt::format("known_mass: {}\n", e.known_mass ? "true" : "false");
  y += fmt::format("consistency: {{projected: {}, margin: {}, distance: {}}}  # {}\n", e.projected ? "true" : "false",
                   num(e.margin), num(e.distance), e.status);
  y += fmt::format("fit: {{samples: {}, lags: {}, condition: {}, estimator: {}}}\n", e.samples, e.lags,
                   num(e.condition), e.instrumented ? "instrumental variables (reference motion)" : "least squares");
  if (e.tare_samples > 0)
    y += fmt::format(
        "tare: {{samples: {}, standard: {}}}  # the arm's own error along XX..M{}, from the runs without the "
        "payload, taken out\n",
        e.tare_samples, list(Eigen::VectorXd(e.tare)), e.link);
  y += fmt::format("rms_without_payload: {}  # N m per joint: measured minus the arm's model\n", list(e.rms_without));
  y += fmt::format("rms_with_payload: {}  # N m per joint: minus the arm's and the payload's\n", list(e.rms_with));
  y += fmt::format("standard:  # link {}'s standard parameters added by the payload, its model frame\n", e.link);
  for (int i = 0; i < kInertialParameters; ++i)
    y += fmt::format("  {}{}: {}\n", payload_standard_names()[static_cast<std::size_t>(i)], e.link, num(e.standard(i)));
  y += "# Controllers' load settings, each in the flange frame above (docs/payload.md):\n";
  y += "franka:  # libfranka Robot::setLoad(load_mass, F_x_Cload, load_inertia)\n";
  std::string franka = franka_load(p);
  for (std::size_t at = 0; at < franka.size();) {
    const std::size_t end = franka.find('\n', at);
    y += "  " + franka.substr(at, end - at) + "\n";
    at = end == std::string::npos ? franka.size() : end + 1;
  }
  y += fmt::format("ur: \"{}\"\n", ur_payload(p));
  y += fmt::format("kuka: \"{}\"\n", kuka_load(p));
  return y;
}

PayloadFile read_payload_yaml(const std::string& file) {
  const YAML::Node root = io::load_yaml_file(file);
  if (!root.IsMap() || !root["format"] || root["format"].as<std::string>() != "symoro-payload 1")
    throw DataError(file, 0, "not a payload file (format: symoro-payload 1; dynid payload writes one)");
  io::check_keys(root,
                 {"format", "robot", "flange", "flange_in_link", "payload", "std_dev", "known_mass", "consistency",
                  "fit", "tare", "rms_without_payload", "rms_with_payload", "standard", "franka", "ur", "kuka"},
                 file, "a payload file");
  const YAML::Node p = root["payload"];
  if (!p || !p.IsMap()) throw DataError(file, 0, "no payload: section");
  io::check_keys(p, {"mass", "com", "inertia"}, file, "payload");
  PayloadFile out;
  out.robot = root["robot"] ? root["robot"].as<std::string>() : "";
  out.flange = root["flange"] ? root["flange"].as<std::string>() : "";
  out.payload.mass = io::yaml_number(p["mass"], file, "payload mass");
  if (!(out.payload.mass > 0)) throw DataError(file, p["mass"].Mark().line + 1, "payload mass: must be positive");
  out.payload.com = io::yaml_numbers(p["com"], 3, file, "payload com");
  const Eigen::VectorXd i = io::yaml_numbers(p["inertia"], 6, file, "payload inertia (ixx iyy izz ixy ixz iyz)");
  out.payload.inertia << i(0), i(3), i(4), i(3), i(1), i(5), i(4), i(5), i(2);
  if (const YAML::Node f = root["flange_in_link"]) {
    io::check_keys(f, {"link", "xyz", "rpy"}, file, "flange_in_link");
    out.link = static_cast<int>(io::yaml_number(f["link"], file, "flange_in_link link"));
    out.flange_in_link = pose_at(f, file, "flange_in_link");
  }
  return out;
}

std::string payload_urdf(const PayloadInertial& p, const std::string& parent, const std::string& name,
                         const Eigen::Isometry3d& flange_in_parent) {
  const Eigen::Matrix3d& I = p.inertia;
  std::string u;
  u += fmt::format("  <link name=\"{}\">\n    <inertial>\n", name);
  u += fmt::format("      <origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/>\n", num(p.com.x()), num(p.com.y()), num(p.com.z()));
  u += fmt::format("      <mass value=\"{}\"/>\n", num(p.mass));
  u += fmt::format("      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n", num(I(0, 0)),
                   num(I(0, 1)), num(I(0, 2)), num(I(1, 1)), num(I(1, 2)), num(I(2, 2)));
  u += "    </inertial>\n  </link>\n";
  u += fmt::format("  <joint name=\"{}_joint\" type=\"fixed\">\n    <parent link=\"{}\"/>\n    <child link=\"{}\"/>\n",
                   name, parent, name);
  const Eigen::Vector3d t = flange_in_parent.translation(), rpy = rpy_of(flange_in_parent.linear());
  u += fmt::format("    <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>\n  </joint>\n", num(t.x() + 0.0), num(t.y() + 0.0),
                   num(t.z() + 0.0), num(rpy.x()), num(rpy.y()), num(rpy.z()));
  return u;
}

std::string urdf_with_payload(const std::string& urdf, const PayloadInertial& p, const std::string& parent,
                              const std::string& name, const Eigen::Isometry3d& flange_in_parent) {
  const std::size_t end = urdf.rfind("</robot>");
  if (end == std::string::npos) throw std::invalid_argument("the URDF has no </robot>");
  if (urdf.find("<link name=\"" + parent + "\"") == std::string::npos)
    throw std::invalid_argument("the URDF has no link '" + parent + "' to hold the payload");
  if (urdf.find("<link name=\"" + name + "\"") != std::string::npos)
    throw std::invalid_argument("the URDF has a link '" + name + "' already");
  return urdf.substr(0, end) + "  <!-- dynid payload -->\n" + payload_urdf(p, parent, name, flange_in_parent) +
         urdf.substr(end);
}

PrincipalLoad principal_load(const Eigen::Matrix3d& inertia) {
  Eigen::Vector3d moments;
  Eigen::Matrix3d axes;
  principal_axes(inertia, moments, axes);
  // The order and signs of the axes (a rotation) nearest the flange's own: the largest trace.
  PrincipalLoad best;
  double trace = -10;
  std::array<int, 3> order{{0, 1, 2}};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R;
      for (int k = 0; k < 3; ++k) R.col(k) = ((signs >> k) & 1 ? -1.0 : 1.0) * axes.col(order[k]);
      if (R.determinant() < 0 || R.trace() <= trace + 1e-12) continue;
      trace = R.trace();
      best.axes = R;
      best.moments = Eigen::Vector3d(moments(order[0]), moments(order[1]), moments(order[2]));
    }
  } while (std::next_permutation(order.begin(), order.end()));
  const Eigen::Matrix3d& R = best.axes;  // R = Rz(A) Ry(B) Rx(C)
  best.abc = Eigen::Vector3d(std::atan2(R(1, 0), R(0, 0)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
                             std::atan2(R(2, 1), R(2, 2))) *
             kDeg;
  return best;
}

std::string franka_load(const PayloadInertial& p) {
  const Eigen::Matrix3d& I = p.inertia;
  std::string out = fmt::format("mass: {}\n", num(p.mass));
  out += fmt::format("F_x_Cload: {}\n", list(Eigen::VectorXd(p.com)));
  Eigen::VectorXd column_major(9);
  for (int c = 0, k = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) column_major(k++) = I(r, c);
  out += fmt::format("load_inertia: {}", list(column_major));
  return out;
}

std::string ur_payload(const PayloadInertial& p) {
  return fmt::format("set_target_payload({}, {}, {})", num(p.mass), list(Eigen::VectorXd(p.com)), six(p.inertia));
}

std::string kuka_load(const PayloadInertial& p) {
  const PrincipalLoad l = principal_load(p.inertia);
  auto f = [](double v) { return fmt::format("{:.6g}", v); };
  return fmt::format("{{M {},CM {{X {},Y {},Z {},A {},B {},C {}}},J {{X {},Y {},Z {}}}}}", f(p.mass),
                     f(p.com.x() * 1000), f(p.com.y() * 1000), f(p.com.z() * 1000), f(l.abc(0)), f(l.abc(1)),
                     f(l.abc(2)), f(l.moments(0)), f(l.moments(1)), f(l.moments(2)));
}

}  // namespace symoro::payload
