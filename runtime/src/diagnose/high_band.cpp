#include "symoro/diagnose/high_band.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "symoro/control/ffpd.hpp"
#include "symoro/error.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::diagnose {

Eigen::VectorXd high_band_rms(const io::Log& log, const BacklashFitOptions& options) {
  preprocess::Options po;
  po.derivative_cutoff = options.light_hz;
  const double base = log.meta.sample_time > 0 ? log.meta.sample_time : 0.001;
  const preprocess::Samples s = preprocess::preprocess(log, base, po);
  const auto sections = preprocess::butterworth_lowpass(4, options.band_hz, 1.0 / base);
  const int padding = preprocess::zero_phase_padding(sections);
  const Eigen::Index n = s.tau.cols();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n);
  long count = 0;
  for (Eigen::Index a = 0; a < s.tau.rows();) {
    Eigen::Index b = a + 1;
    while (b < s.tau.rows() && (s.piece.empty() || s.piece[b] == s.piece[a])) ++b;
    if (b - a > padding + 1) {
      preprocess::Channels low = s.tau.middleRows(a, b - a);
      preprocess::filtfilt(sections, padding, low);
      sum += (s.tau.middleRows(a, b - a) - low).colwise().squaredNorm().transpose();
      count += static_cast<long>(b - a);
    }
    a = b;
  }
  return (sum / static_cast<double>(std::max(1L, count))).cwiseSqrt();
}

namespace {

// Rows k and k + lag one period per row apart (no dropped read between them).
bool consecutive(const io::Log& log, Eigen::Index k, int lag, double period) {
  return std::abs(log.time(k + lag) - log.time(k) - lag * period) < 0.5 * period;
}

}  // namespace

LoopFloor loop_floor(const io::Log& log, const twin::TwinConfig& c, const BacklashFitOptions& options) {
  const Eigen::Index n = log.joints(), rows = log.samples();
  const std::string name = log.meta.trajectory.empty() ? "log" : log.meta.trajectory;
  if (!log.has_references()) throw DataError(name, 0, "the loop's floor needs the log's reference columns");
  if (static_cast<std::size_t>(n) != c.servos.size())
    throw DataError(
        name, 0,
        "the log has " + std::to_string(n) + " joints, the twin description " + std::to_string(c.servos.size()));
  const control::FfpdGains g = c.controller.gains();
  const double T = c.controller.period;
  // The law's torque at every row, as the servo realizes it (quantized current, its limit).
  Eigen::MatrixXd command(rows, n);
  for (Eigen::Index k = 0; k < rows; ++k) {
    const Eigen::VectorXd u =
        control::ffpd_command(g, log.q.row(k).transpose(), log.qd.row(k).transpose(), log.q_ref.row(k).transpose(),
                              log.qd_ref.row(k).transpose(), log.qdd_ref.row(k).transpose());
    for (Eigen::Index j = 0; j < n; ++j) {
      const auto& s = c.servos[static_cast<std::size_t>(j)];
      const double limit = std::floor(s.current_limit / s.current_unit) * s.current_unit;
      command(k, j) = s.torque_constant *
                      std::clamp(std::round(u(j) / s.torque_constant / s.current_unit) * s.current_unit, -limit, limit);
    }
  }
  // The residual at one lag (rows without a command that lag before: 0).
  auto residual_at = [&](int lag) {
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(rows, n);
    for (Eigen::Index k = 0; k + lag < rows; ++k)
      if (consecutive(log, k, lag, T)) r.row(k + lag) = log.tau.row(k + lag) - command.row(k);
    return r;
  };
  LoopFloor f;
  double best = -1;
  for (int lag = 0; lag <= 2; ++lag) {
    const double sum = residual_at(lag).squaredNorm();
    if (best < 0 || sum < best) best = sum, f.lag = lag;
  }
  io::Log residual = log;
  residual.tau = residual_at(f.lag);
  f.law_rms =
      (residual.tau.colwise().squaredNorm() / std::max<double>(1.0, static_cast<double>(rows))).cwiseSqrt().transpose();
  f.rms = high_band_rms(residual, options);
  // Encoder noise: the position's second difference in counts on 50 ms blocks, its median over
  // blocks (a play's chatter or a fast move raises a few), against the same of the logged
  // position smoothed (20 Hz, zero phase: the motion) and quantized again with a trial noise:
  // quantization alone gives the motion's count transitions, which a slow joint seldom makes.
  const int per_block = std::max(3, static_cast<int>(std::lround(0.05 / T)));
  const auto smooth = preprocess::butterworth_lowpass(2, 20.0, 1.0 / T);
  const int padding = preprocess::zero_phase_padding(smooth);
  f.encoder_noise_per_joint = Eigen::VectorXd::Zero(n);
  auto median_block_variance = [&](const Eigen::VectorXd& counts) {
    std::vector<double> blocks;
    double sum = 0;
    int m = 0;
    for (Eigen::Index k = 1; k + 1 < rows; ++k) {
      if (!consecutive(log, k - 1, 2, T)) continue;
      const double d2 = counts(k + 1) - 2 * counts(k) + counts(k - 1);
      sum += d2 * d2;
      if (++m == per_block) blocks.push_back(sum / m), sum = 0, m = 0;
    }
    if (blocks.empty()) return 0.0;
    std::nth_element(blocks.begin(), blocks.begin() + static_cast<std::ptrdiff_t>(blocks.size() / 2), blocks.end());
    return blocks[blocks.size() / 2];
  };
  if (rows > padding + 2)
    for (Eigen::Index j = 0; j < n; ++j) {
      const int counts = c.servos[static_cast<std::size_t>(j)].encoder_counts;
      if (counts <= 0) continue;
      const double scale = counts / (2 * M_PI);
      const Eigen::VectorXd logged = scale * log.q.col(j);
      preprocess::Channels motion = logged;
      preprocess::filtfilt(smooth, padding, motion);
      const double target = median_block_variance(logged);
      std::mt19937_64 gen(12345);
      Eigen::VectorXd gauss(rows);
      std::normal_distribution<double> normal;
      for (Eigen::Index k = 0; k < rows; ++k) gauss(k) = normal(gen);
      auto simulated = [&](double sd) {
        const Eigen::VectorXd q = (motion.col(0) + sd * gauss).array().round().matrix();
        return median_block_variance(q);
      };
      double lo = 0, hi = 3;
      if (simulated(lo) >= target) continue;
      for (int it = 0; it < 14; ++it) {
        const double mid = 0.5 * (lo + hi);
        (simulated(mid) < target ? lo : hi) = mid;
      }
      f.encoder_noise_per_joint(j) = 0.5 * (lo + hi);
    }
  std::vector<double> v(f.encoder_noise_per_joint.data(), f.encoder_noise_per_joint.data() + n);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  f.encoder_noise = v.empty() ? 0.0 : v[v.size() / 2];
  return f;
}

}  // namespace symoro::diagnose
