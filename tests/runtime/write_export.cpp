// Writes a CSV as a robot's own controller could export it, for the command-line tests of the
// any-robot workflow: `write_export <robot> <file> <seconds> <seed>` for rx90, stanford_rrp or
// ur5 (from its URDF's inertials); `[velocity Hz]`: the velocity columns through a first-order
// low-pass at that corner, as a controller's own causal estimate (late by its filter; 0: none);
// `[contact J,start,duration,torque]`: an external torque on joint J (1-based) for `duration` s
// from `start` s after the log's first row, with 2 ms ramps, that the motor's torque gives way to
// (the motion is the same: tau = ID - tau_ext), for the momentum observer's test (`-`: none);
// `[payload m,cx,cy,cz,ixx,iyy,izz,ixy,ixz,iyz]` (ur5): a body the arm carries that the log's
// torque includes, mass kg, CoM m and inertia kg m^2 about it in the URDF tip link's frame
// (robot.yaml urdf.tip_in_last_frame), for dynid payload's test. The
// motion and torque come from the robot's generated model (synthetic_log.hpp) with Coulomb
// friction (in the truth; a `rigid` model lacks it), an offset of -0.06 N m on the last joint,
// noise and 5 % stale rows; columns stamp_ms, mode (text), <joint>_pos, _vel (deg, deg/s; m,
// m/s for a prismatic joint), <joint>_eff (N m; N). A <file> ending in .json is instead the spec
// of a ROS 2 bag of the same log for tests/bags/write_bag.mjs, whose MCAP file is <file> with
// .mcap for .json (synthetic_log.hpp: write_bag_spec).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>
#include <symoro/ur5.hpp>
#include <yaml-cpp/yaml.h>

#include "synthetic_log.hpp"
#include "test_support.hpp"

namespace {

// A controller's causal velocity estimate: y += (1 - exp(-2 pi fc dt)) (qd - y), from rest. A
// stale row (the logger repeated the row before) repeats the estimate too.
void lag_velocity(symoro::io::Log& log, double corner_hz) {
  if (!(corner_hz > 0)) return;
  const Eigen::MatrixXd raw = log.qd;
  Eigen::RowVectorXd y = log.qd.row(0);
  for (Eigen::Index k = 1; k < log.qd.rows(); ++k) {
    if (log.q.row(k) == log.q.row(k - 1) && raw.row(k) == raw.row(k - 1)) {
      log.qd.row(k) = log.qd.row(k - 1);
      continue;
    }
    const double a = 1 - std::exp(-2 * 3.14159265358979323846 * corner_hz * (log.time(k) - log.time(k - 1)));
    y += a * (log.qd.row(k) - y);
    log.qd.row(k) = y;
  }
}

// The contact a command line names (joint 0: none).
struct Contact {
  int joint = 0;
  double start = 0, duration = 0, torque = 0;
  double at(double t) const {
    const double ramp = 0.002, in = t - start, left = start + duration - t;
    if (joint == 0 || in <= 0 || left <= 0) return 0;
    return torque * std::min({1.0, in / ramp, left / ramp});
  }
};

// The motor gives way to the contact; a stale row repeats the row before as it was logged.
void add_contact(symoro::io::Log& log, const Contact& c) {
  if (c.joint == 0) return;
  const Eigen::MatrixXd q = log.q, qd = log.qd;
  for (Eigen::Index k = 0; k < log.tau.rows(); ++k) {
    if (k > 0 && q.row(k) == q.row(k - 1) && qd.row(k) == qd.row(k - 1)) {
      log.tau.row(k) = log.tau.row(k - 1);
      continue;
    }
    log.tau(k, c.joint - 1) -= c.at(log.time(k) - log.time(0));
  }
}

template <class Model>
int write(const std::string& file, double seconds, unsigned seed, double velocity_hz) {
  symoro::test::Random rng(23);
  const Eigen::Matrix<double, Model::np, 1> truth =
      Model::base_from_standard(symoro::test::random_standard_parameters<Model>(rng).s);
  symoro::io::Log log = symoro::test::synthesize<Model>("export", truth, seconds, seed, 0.05,
                                                        symoro::test::offset_on<Model>(Model::nq, -0.06));
  lag_velocity(log, velocity_hz);
  symoro::test::write_export_csv<Model>(log, file);
  return 0;
}

// A robot symoroc model made from its URDF: the truth is the URDF's own inertials (robot.yaml's
// nominal parameters), with Coulomb friction the URDF does not have (and the offset).
// A payload given in the tip link's frame T as the last link's standard parameters (frame L):
// c_L = R c + p, I_L = R I R' + m (|c_L|^2 1 - c_L c_L'), written out here from robot.yaml.
struct Payload {
  double m = 0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
};

template <class Model>
void add_payload(Eigen::Matrix<double, Model::ns, 1>& s, const Payload& p, const YAML::Node& tip) {
  if (!(p.m > 0)) return;
  const auto xyz = tip["xyz"].as<std::vector<double>>(), rpy = tip["rpy"].as<std::vector<double>>();
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d c = R * p.c + Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  const Eigen::Matrix3d I =
      R * p.I * R.transpose() + p.m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  const double value[10] = {I(0, 0), I(0, 1),    I(0, 2),    I(1, 1),    I(1, 2),
                            I(2, 2), p.m * c(0), p.m * c(1), p.m * c(2), p.m};
  const char* families[10] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"};
  for (int i = 0; i < Model::ns; ++i)
    for (int f = 0; f < 10; ++f)
      if (Model::standard_parameters[i].joint == Model::nq &&
          std::string(Model::standard_parameters[i].family) == families[f])
        s(i) += value[f];
}

template <class Model>
int write_from_nominal(const std::string& file, double seconds, unsigned seed, const std::vector<double>& coulomb,
                       const Contact& contact, const Payload& payload = {}) {
  const YAML::Node nominal =
      YAML::LoadFile(std::string(SYMORO_ROBOTS_DIR) + "/" + Model::robot_name + "/robot.yaml")["nominal"];
  Eigen::Matrix<double, Model::ns, 1> s;
  for (int i = 0; i < Model::ns; ++i) {
    const auto& p = Model::standard_parameters[i];
    s(i) = std::string(p.family) == "FS" ? coulomb.at(p.joint - 1) : nominal[p.name].template as<double>();
  }
  add_payload<Model>(s, payload,
                     YAML::LoadFile(std::string(SYMORO_ROBOTS_DIR) + "/" + Model::robot_name +
                                    "/robot.yaml")["urdf"]["tip_in_last_frame"]);
  symoro::io::Log log = symoro::test::synthesize<Model>("export", Model::base_from_standard(s), seconds, seed, 0.05,
                                                        symoro::test::offset_on<Model>(Model::nq, -0.06));
  add_contact(log, contact);
  if (std::filesystem::path(file).extension() == ".json")
    symoro::test::write_bag_spec<Model>(log, file, std::filesystem::path(file).replace_extension(".mcap"));
  else
    symoro::test::write_export_csv<Model>(log, file);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5 || argc > 8) {
    std::fprintf(stderr,
                 "usage: write_export rx90|stanford_rrp|ur5 <file.csv> <seconds> <seed> [velocity Hz] "
                 "[contact J,start,duration,torque (ur5) or -] [payload m,cx,cy,cz,ixx,iyy,izz,ixy,ixz,iyz (ur5)]\n");
    return 2;
  }
  Contact contact;
  Payload payload;
  double in[10];
  if (argc == 8) {
    if (std::sscanf(argv[7], "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &in[0], &in[1], &in[2], &in[3], &in[4], &in[5],
                    &in[6], &in[7], &in[8], &in[9]) != 10) {
      std::fprintf(stderr, "write_export: payload '%s' is not m,cx,cy,cz,ixx,iyy,izz,ixy,ixz,iyz\n", argv[7]);
      return 2;
    }
    payload.m = in[0];
    payload.c = Eigen::Vector3d(in[1], in[2], in[3]);
    payload.I << in[4], in[7], in[8], in[7], in[5], in[9], in[8], in[9], in[6];
  }
  if (argc >= 7 && std::string(argv[6]) != "-" &&
      std::sscanf(argv[6], "%d,%lf,%lf,%lf", &contact.joint, &contact.start, &contact.duration, &contact.torque) != 4) {
    std::fprintf(stderr, "write_export: contact '%s' is not J,start,duration,torque\n", argv[6]);
    return 2;
  }
  const std::string robot = argv[1];
  const double seconds = std::stod(argv[3]);
  const unsigned seed = static_cast<unsigned>(std::stoul(argv[4]));
  const double velocity_hz = argc >= 6 ? std::stod(argv[5]) : 0;
  if (robot == "rx90") return write<symoro::rx90::Model>(argv[2], seconds, seed, velocity_hz);
  if (robot == "stanford_rrp") return write<symoro::stanford_rrp::Model>(argv[2], seconds, seed, velocity_hz);
  if (robot == "ur5")
    return write_from_nominal<symoro::ur5::Model>(argv[2], seconds, seed, {1.5, 1.5, 1.0, 0.3, 0.3, 0.3}, contact,
                                                  payload);
  std::fprintf(stderr, "unknown robot %s\n", robot.c_str());
  return 2;
}
