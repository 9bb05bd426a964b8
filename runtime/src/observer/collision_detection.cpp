#include "symoro/observer/collision_detection.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::observer {

Eigen::MatrixXd observe_log(MomentumObserver& observer, const io::Log& log) {
  const int n = observer.nq();
  if (log.joints() != n)
    throw std::invalid_argument(
        fmt::format("observe_log: the log has {} joints, the observer's model {}", log.joints(), n));
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(log.samples(), n);
  // Row-major copies of one sample: the log's matrices are column-major.
  Eigen::VectorXd q(n), qd(n), tau(n);
  Eigen::Index last = 0;  // the last row stepped
  for (Eigen::Index k = 0; k < log.samples(); ++k) {
    // A stale row (a logger repeating the row before under a new stamp) is no new sample: r holds,
    // and the next new row steps over both intervals.
    if (k > 0 && log.q.row(k) == log.q.row(k - 1) && log.qd.row(k) == log.qd.row(k - 1) &&
        log.tau.row(k) == log.tau.row(k - 1)) {
      r.row(k) = r.row(k - 1);
      continue;
    }
    q = log.q.row(k).transpose();
    qd = log.qd.row(k).transpose();
    tau = log.tau.row(k).transpose();
    if (k == 0) {
      observer.reset(q.data(), qd.data(), tau.data());
      continue;
    }
    r.row(k) = observer.update(q.data(), qd.data(), tau.data(), log.time(k) - log.time(last)).transpose();
    last = k;
  }
  return r;
}

ObserverThresholds observer_thresholds(const std::vector<Eigen::MatrixXd>& residuals,
                                       const std::vector<Eigen::VectorXd>& times, const Eigen::VectorXd& gain,
                                       const ThresholdOptions& options) {
  if (residuals.empty() || residuals.size() != times.size())
    throw std::invalid_argument("observer_thresholds: no calibration residuals (or times and residuals differ)");
  if (!(options.false_alarms_per_hour > 0))
    throw std::invalid_argument("observer_thresholds: the false-alarm rate must be positive");
  const Eigen::Index n = residuals.front().cols();
  const double settle = options.settle_time_constants / gain.minCoeff();
  ObserverThresholds t;
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), sq = Eigen::VectorXd::Zero(n);
  std::vector<std::pair<std::size_t, Eigen::Index>> used;  // (run, first row)
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    const Eigen::VectorXd& time = times[i];
    Eigen::Index first = 0;
    while (first < time.size() && time(first) - time(0) < settle) ++first;
    used.emplace_back(i, first);
    for (Eigen::Index k = first; k < time.size(); ++k) {
      sum += residuals[i].row(k).transpose();
      sq += residuals[i].row(k).transpose().cwiseAbs2();
      ++t.samples;
    }
    if (time.size() > first) t.seconds += time(time.size() - 1) - time(first);
  }
  if (t.samples < 100)
    throw std::invalid_argument(fmt::format(
        "observer_thresholds: {} calibration samples after the residual settles ({:.3g} s per run): too few", t.samples,
        settle));
  t.center = sum / t.samples;
  t.spread = (sq / t.samples - t.center.cwiseAbs2()).cwiseMax(0).cwiseSqrt();
  t.false_alarms_per_hour = options.false_alarms_per_hour;
  t.peak_margin = options.peak_margin;
  t.window = options.window_time_constants / gain.minCoeff();
  // Each joint's largest |r - center| per whole window, every run cut from its settled start.
  std::vector<Eigen::VectorXd> maxima;
  t.peak = Eigen::VectorXd::Zero(n);
  for (const auto& [i, first] : used) {
    const Eigen::VectorXd& time = times[i];
    Eigen::VectorXd m = Eigen::VectorXd::Zero(n);
    double from = first < time.size() ? time(first) : 0;
    for (Eigen::Index k = first; k < time.size(); ++k) {
      if (time(k) - from >= t.window) maxima.push_back(m), m.setZero(), from += t.window;
      m = m.cwiseMax((residuals[i].row(k).transpose() - t.center).cwiseAbs());
      t.peak = t.peak.cwiseMax(m);
    }
  }
  t.windows = static_cast<int>(maxima.size());
  if (t.windows < 10)
    throw std::invalid_argument(
        fmt::format("observer_thresholds: the calibration holds {} windows of {:.3g} s after the residual settles; "
                    "at least 10 are needed ({:.3g} s of motion without contact)",
                    t.windows, t.window, 10 * t.window + settle));
  // Gumbel by moments: beta = s sqrt(6) / pi, mu = mean - 0.5772 beta; the level a window passes
  // with probability p is mu - beta ln(-ln(1 - p)).
  const double p = std::min(0.5, options.false_alarms_per_hour * t.window / 3600 / static_cast<double>(n));
  t.tail.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    double mean = 0, square = 0;
    for (const auto& m : maxima) mean += m(j), square += m(j) * m(j);
    mean /= t.windows;
    const double sd = std::sqrt(std::max(0.0, square / t.windows - mean * mean));
    const double beta = sd * std::sqrt(6.0) / 3.14159265358979323846, mu = mean - 0.5772156649015329 * beta;
    t.tail(j) = mu - beta * std::log(-std::log1p(-p));
  }
  t.threshold = t.tail;
  for (const auto& [i, first] : used) {
    const Eigen::Index rows = residuals[i].rows() - first;
    t.tail_alarms += static_cast<int>(collision_events(times[i].tail(rows), residuals[i].bottomRows(rows), t).size());
  }
  t.threshold = t.tail.cwiseMax(options.peak_margin * t.peak);
  return t;
}

std::vector<CollisionEvent> collision_events(const Eigen::VectorXd& time, const Eigen::MatrixXd& residual,
                                             const ObserverThresholds& thresholds, double merge_within) {
  std::vector<CollisionEvent> out;
  for (Eigen::Index j = 0; j < residual.cols(); ++j) {
    bool open = false;
    CollisionEvent e;
    const std::size_t first = out.size();  // this joint's events begin here
    const auto close = [&] {
      if (out.size() > first && e.start - out.back().end <= merge_within) {
        CollisionEvent& last = out.back();
        last.end = e.end;
        if (std::abs(e.peak) > std::abs(last.peak)) last.peak = e.peak, last.peak_time = e.peak_time;
      } else {
        out.push_back(e);
      }
      open = false;
    };
    for (Eigen::Index k = 0; k < residual.rows(); ++k) {
      const double d = residual(k, j) - thresholds.center(j);
      if (std::abs(d) > thresholds.threshold(j)) {
        if (!open) e = CollisionEvent{static_cast<int>(j), time(k), time(k), 0, time(k)}, open = true;
        e.end = time(k);
        if (std::abs(d) > std::abs(e.peak)) e.peak = d, e.peak_time = time(k);
      } else if (open) {
        close();
      }
    }
    if (open) close();
  }
  std::stable_sort(out.begin(), out.end(), [](const CollisionEvent& a, const CollisionEvent& b) {
    return a.start < b.start || (a.start == b.start && a.joint < b.joint);
  });
  return out;
}

namespace {

std::string list(const Eigen::VectorXd& v) {
  std::string s;
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + io::number_text(v(i));
  return "[" + s + "]";
}

}  // namespace

std::string thresholds_yaml(const ObserverThresholds& t, const std::vector<std::string>& joints,
                            const std::string& robot, const std::string& model, const Eigen::VectorXd& gain,
                            const std::string& calibrated_on) {
  std::string names;
  for (const auto& j : joints) names += (names.empty() ? "" : ", ") + fmt::format("\"{}\"", j);
  return fmt::format(
      "# The momentum observer's band per joint: an event when |r - center| > threshold (dynid observer).\n"
      "# threshold = max(tail, peak_margin * calibration peak); tail: the level a window passes at\n"
      "# false_alarms_per_hour (all joints together) by a Gumbel fit of each joint's window maxima.\n"
      "# Units: N m (revolute), N (prismatic).\n"
      "robot: \"{}\"\nmodel: \"{}\"\njoints: [{}]\ngain: {}  # K, 1/s\n"
      "false_alarms_per_hour: {}\npeak_margin: {}\ncenter: {}\nspread: {}\nthreshold: {}\n"
      "calibration:\n  on: \"{}\"\n  samples: {}\n  seconds: {}\n  window: {}  # s\n  windows: {}\n"
      "  peak: {}  # max |r - center|\n  tail: {}  # the Gumbel level\n"
      "  tail_alarms: {}  # events the tail band alone raises on the calibration runs\n",
      robot, model, names, list(gain), io::number_text(t.false_alarms_per_hour), io::number_text(t.peak_margin),
      list(t.center), list(t.spread), list(t.threshold), calibrated_on, t.samples, io::number_text(t.seconds),
      io::number_text(t.window), t.windows, list(t.peak), list(t.tail), t.tail_alarms);
}

ThresholdsFile read_thresholds_yaml(const std::string& file, const std::vector<std::string>& joints) {
  const YAML::Node root = io::load_yaml_file(file);
  if (!root.IsMap()) throw DataError(file, 1, "a thresholds file is a mapping (dynid observer writes one)");
  io::check_keys(root,
                 {"robot", "model", "joints", "gain", "false_alarms_per_hour", "peak_margin", "center", "spread",
                  "threshold", "calibration"},
                 file, "a thresholds file");
  const auto line = [](const YAML::Node& n) { return n.Mark().line + 1; };
  const auto vector = [&](const char* key) {
    const YAML::Node n = root[key];
    if (!n || !n.IsSequence() || n.size() != joints.size())
      throw DataError(file, n ? line(n) : 0, fmt::format("{} must list {} numbers, one per joint", key, joints.size()));
    Eigen::VectorXd v(static_cast<Eigen::Index>(joints.size()));
    for (std::size_t i = 0; i < joints.size(); ++i) {
      double x = 0;
      if (!YAML::convert<double>::decode(n[i], x) || !std::isfinite(x))
        throw DataError(file, line(n[i]), fmt::format("{}[{}] is not a finite number", key, i));
      v(static_cast<Eigen::Index>(i)) = x;
    }
    return v;
  };
  const YAML::Node names = root["joints"];
  if (!names || !names.IsSequence() || names.size() != joints.size())
    throw DataError(file, names ? line(names) : 0, fmt::format("joints must list the model's {}", joints.size()));
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (!names[i].IsScalar() || names[i].Scalar() != joints[i])
      throw DataError(file, line(names[i]),
                      fmt::format("joint {} is '{}', the model's is '{}'", i + 1,
                                  names[i].IsScalar() ? names[i].Scalar() : "?", joints[i]));
  ThresholdsFile out;
  out.robot = root["robot"] && root["robot"].IsScalar() ? root["robot"].Scalar() : "";
  out.model = root["model"] && root["model"].IsScalar() ? root["model"].Scalar() : "";
  out.gain = vector("gain");
  out.thresholds.center = vector("center");
  out.thresholds.spread = vector("spread");
  out.thresholds.threshold = vector("threshold");
  for (Eigen::Index j = 0; j < out.gain.size(); ++j) {
    if (!(out.gain(j) > 0)) throw DataError(file, line(root["gain"]), "every gain must be positive");
    if (!(out.thresholds.threshold(j) > 0))
      throw DataError(file, line(root["threshold"]), "every threshold must be positive");
  }
  if (root["false_alarms_per_hour"]) out.thresholds.false_alarms_per_hour = root["false_alarms_per_hour"].as<double>(0);
  if (root["peak_margin"]) out.thresholds.peak_margin = root["peak_margin"].as<double>(0);
  return out;
}

}  // namespace symoro::observer
