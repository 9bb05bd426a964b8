// Logs a robot's own controller could have written, synthesized from a generated model: a
// smooth multi-sine excitation through each joint's range (three sines, 35 % of the range),
// stamps 1 ms apart with +-0.15 ms of jitter starting at 12.5 s (a controller's clock), 5 % stale
// rows (the previous state again under a new stamp), the model's torque at the truth plus
// effects the code under test is not told about (a constant offset per joint) and white noise.
#pragma once

#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <fmt/format.h>

#include "symoro/io/log.hpp"
#include "symoro/model_info.hpp"

namespace symoro::test {

// A constant offset on one joint (1-based), zero on the others.
template <class Model>
Eigen::VectorXd offset_on(int joint, double value) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(Model::nq);
  v(joint - 1) = value;
  return v;
}

// One synthesized log: q(t) a sum of three sines per joint around the middle of its range.
template <class Model>
io::Log synthesize(const std::string& name, const Eigen::Matrix<double, Model::np, 1>& phi, double seconds,
                   unsigned seed, double noise, const Eigen::VectorXd& offset = {}) {
  constexpr double kPi = 3.14159265358979323846;
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  constexpr int n = Model::nq, waves = 3;
  Eigen::MatrixXd amp(n, waves), freq(n, waves), phase(n, waves);
  Eigen::VectorXd mid(n);
  for (int j = 0; j < n; ++j) {
    const auto& J = Model::joints[j];
    mid(j) = 0.5 * (J.lower + J.upper);
    for (int k = 0; k < waves; ++k) {
      amp(j, k) = 0.35 * 0.5 * (J.upper - J.lower) / waves * (0.6 + 0.4 * u(gen));
      freq(j, k) = 2 * kPi * (0.15 + 0.5 * u(gen));
      phase(j, k) = 2 * kPi * u(gen);
    }
  }
  const int rows = static_cast<int>(seconds / 0.001);
  io::Log log;
  log.meta.robot = Model::robot_name;
  log.meta.trajectory = name;
  log.meta.trial = 1;
  log.meta.source = "robot";
  log.meta.sample_time = 0.001;
  for (const auto& J : Model::joints) log.meta.joints.emplace_back(J.name);
  log.time.resize(rows);
  log.q.resize(rows, n);
  log.qd.resize(rows, n);
  log.tau.resize(rows, n);
  Vec q, qd, qdd, tau;
  for (int i = 0; i < rows; ++i) {
    // Stamps: 1 ms apart with +-0.15 ms of jitter; the log starts at 12.5 s (a controller's clock).
    log.time(i) = 12.5 + 0.001 * i + (i > 0 ? 0.00015 * (2 * u(gen) - 1) : 0.0);
    if (i > 0 && u(gen) < 0.05) {  // a stale row: the previous state again, under a new stamp
      log.q.row(i) = log.q.row(i - 1);
      log.qd.row(i) = log.qd.row(i - 1);
      log.tau.row(i) = log.tau.row(i - 1);
      continue;
    }
    const double t = log.time(i);
    for (int j = 0; j < n; ++j) {
      q(j) = mid(j), qd(j) = 0, qdd(j) = 0;
      for (int k = 0; k < waves; ++k) {
        const double w = freq(j, k), a = amp(j, k), arg = w * t + phase(j, k);
        q(j) += a * std::sin(arg);
        qd(j) += a * w * std::cos(arg);
        qdd(j) -= a * w * w * std::sin(arg);
      }
    }
    Model::inverse_dynamics(q, qd, qdd, phi, tau);
    if (offset.size() == Model::nq) tau += offset;
    for (int j = 0; j < n; ++j) tau(j) += noise * gauss(gen);
    log.q.row(i) = q.transpose();
    log.qd.row(i) = qd.transpose();
    log.tau.row(i) = tau.transpose();
  }
  return log;
}

// The log a real controller writes of that motion: q from a quantized encoder (counts per
// revolution, plus noise in counts), qd the controller's own estimate (the backward difference of
// the encoder over the nominal period, through a first-order low-pass at `velocity_cutoff` Hz),
// the torque as synthesized (noise included). A stale row stays a copy of the row before.
inline io::Log with_real_sensors(io::Log log, double counts, double encoder_noise, double velocity_cutoff,
                                 unsigned seed) {
  constexpr double kPi = 3.14159265358979323846;
  std::mt19937 gen(seed);
  std::normal_distribution<double> gauss(0, 1);
  const double lsb = 2 * kPi / counts, T = log.meta.sample_time > 0 ? log.meta.sample_time : 0.001;
  const double a = std::exp(-2 * kPi * velocity_cutoff * T);
  const Eigen::MatrixXd q_true = log.q;
  Eigen::RowVectorXd v = Eigen::RowVectorXd::Zero(log.q.cols());
  for (int i = 0; i < log.samples(); ++i) {
    if (i > 0 && q_true.row(i) == q_true.row(i - 1) && log.tau.row(i) == log.tau.row(i - 1)) {  // stale
      log.q.row(i) = log.q.row(i - 1);
      log.qd.row(i) = log.qd.row(i - 1);
      continue;
    }
    for (Eigen::Index j = 0; j < log.q.cols(); ++j)
      log.q(i, j) = std::round(q_true(i, j) / lsb + encoder_noise * gauss(gen)) * lsb;
    if (i > 0) v = a * v + (1 - a) * (log.q.row(i) - log.q.row(i - 1)) / T;
    log.qd.row(i) = v;
  }
  return log;
}

// The log as a robot's controller could export it: a comment line, then stamp_ms, mode (a text
// column), <joint>_pos and _vel (deg, deg/s; m, m/s for a prismatic joint), <joint>_eff (N m; N),
// every number in its shortest round-trip form.
template <class Model>
void write_export_csv(const io::Log& log, const std::filesystem::path& file) {
  constexpr double kPi = 3.14159265358979323846;
  auto unit = [](int j) { return Model::joints[j].type == JointType::Prismatic ? 1.0 : 180 / kPi; };
  std::ofstream out(file);
  out << "# exported by the arm's controller\nstamp_ms,mode";
  for (const char* what : {"pos", "vel", "eff"})
    for (const auto& J : Model::joints) out << "," << J.name << "_" << what;
  out << "\n";
  for (int i = 0; i < log.samples(); ++i) {
    out << fmt::format("{:.17g},run", log.time(i) * 1e3);
    for (int j = 0; j < Model::nq; ++j) out << fmt::format(",{:.17g}", log.q(i, j) * unit(j));
    for (int j = 0; j < Model::nq; ++j) out << fmt::format(",{:.17g}", log.qd(i, j) * unit(j));
    for (int j = 0; j < Model::nq; ++j) out << fmt::format(",{:.17g}", log.tau(i, j));
    out << "\n";
  }
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

// The same log as a ROS 2 driver records it, as the spec of tests/bags/write_bag.mjs: one
// sensor_msgs/msg/JointState per row on /joint_states (the joints' names, SI units, header stamps
// from a time of day), a gripper joint the robot has not among them, a status topic beside, in
// zstd chunks. `out` is the MCAP file the writer is to write.
template <class Model>
void write_bag_spec(const io::Log& log, const std::filesystem::path& spec, const std::filesystem::path& out) {
  std::ofstream o(spec);
  o << "{\"out\":\"" << out.string() << "\",\"compression\":\"zstd\",\"chunked\":true,\"messages\":[";
  const long long start = 1764400000000000000LL;
  for (int i = 0; i < log.samples(); ++i) {
    const long long stamp = start + std::llround(log.time(i) * 1e9);
    std::string names = "\"gripper_joint\"", q = "0.02", qd = "0", tau = "1.5";
    for (int j = 0; j < Model::nq; ++j) {
      names += fmt::format(",\"{}\"", Model::joints[j].name);
      q += fmt::format(",{:.17g}", log.q(i, j));
      qd += fmt::format(",{:.17g}", log.qd(i, j));
      tau += fmt::format(",{:.17g}", log.tau(i, j));
    }
    o << fmt::format(
        "{}{{\"topic\":\"/joint_states\",\"log_time_ns\":\"{}\",\"stamp_sec\":{},\"stamp_nanosec\":{},"
        "\"name\":[{}],\"position\":[{}],\"velocity\":[{}],\"effort\":[{}]}}",
        i ? "," : "", stamp + 300000, stamp / 1000000000, stamp % 1000000000, names, q, qd, tau);
    if (i % 100 == 0)
      o << fmt::format(
          ",{{\"topic\":\"/status\",\"type\":\"std_msgs/msg/String\",\"log_time_ns\":\"{}\","
          "\"data\":\"running\"}}",
          stamp + 400000);
  }
  o << "]}\n";
  if (!o) throw std::runtime_error("cannot write " + spec.string());
}

}  // namespace symoro::test
