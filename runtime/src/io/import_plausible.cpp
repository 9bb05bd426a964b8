// Unit plausibility of an imported log: a unit declared wrong (degrees read as radians, ms read
// as s) gives values that no robot logs; identification would accept them and fit nonsense.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "import_detail.hpp"
#include "symoro/detail/numbers.hpp"
#include "symoro/error.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/number_text.hpp"

namespace symoro::io {

namespace {

using symoro::detail::kPi;

// "Far" beyond a limit: a robot overshoots its soft limits, or is calibrated off, by far less
// than half its range (and than 0.5 rad, for joints of a small range such as a gripper's);
// degrees read as radians multiply positions by 57, so any motion of a few degrees lands far out.
// Prismatic joints: 0.05 m instead of 0.5 rad (mm read as m multiplies by 1000).
constexpr double kRevoluteMargin = 0.5, kPrismaticMargin = 0.05;
// Robot controllers log their state at 10 kHz at most (servo buses: 1 to 8 kHz), and steps over
// 0.5 s cannot resolve the accelerations identification needs. The unit mistakes land 1000
// times off: 1 ms read as s is 1 s, 1 ms read as ms from a file in s is 1 us.
constexpr double kMinStep = 1e-4, kMaxStep = 0.5;

constexpr const char* kOverride = "if the values are right, import with --allow-implausible";
// A logged torque past this many times the joint's effort limit is a unit mistake (mN m read as
// N m, a scale the wrong way round: 1000 times off), not a robot; past kMaxTorque it is no
// torque at all (1e308 imported with rc 0, then identification failed without saying why).
constexpr double kEffortFactor = 5, kMaxTorque = 1e6;
// A pause in a recording: the logger stalled, or two sessions were concatenated. Stale rows and
// jitter are milliseconds; a second and a thousand steps are no sampling.
constexpr double kMaxGap = 1.0, kMaxGapSteps = 1000;

// The logged velocity against the stamps (velocity_agreement): a unit mistake is a factor of 57
// (deg/s beside rad), 1000 (ms) or 60 (rpm); a controller's filtered velocity, jittered stamps
// and stale rows stay within 1 %. A window whose position changes by more than kMaxChange (rad or
// m; 31 rad/s over 0.1 s) spans a wrap of a continuous joint or a glitch; a joint needs
// kMinWindows windows and kMinChange of RMS change per window to be judged.
constexpr double kMinVelocityScale = 0.8, kMaxMismatch = 0.5, kMaxChange = 3.14, kMinChange = 1e-3;
constexpr int kMinWindows = 10;

// The sample (row, joint) whose score most exceeds `floor` (row -1: none does).
struct Worst {
  Eigen::Index row = -1, joint = -1;
};
template <class Score>
Worst worst_sample(Eigen::Index joints, Eigen::Index rows, double floor, Score score) {
  Worst w;
  double most = floor;
  for (Eigen::Index j = 0; j < joints; ++j)
    for (Eigen::Index k = 0; k < rows; ++k)
      if (const double v = score(k, j); v > most) {
        most = v;
        w = {k, j};
      }
  return w;
}

// 3 significant digits are enough evidence; number_text would print 58.70000000000001.
std::string g(double v) { return fmt::format("{:.6g}", v); }

// Positions: the sample farthest beyond its joint's margin, over all joints.
void check_positions(const ImportedLog& imported, const ImportMapping& mapping, const ImportTarget& target) {
  const Log& log = imported.log;
  const std::string file = imported.input.string();
  const Eigen::Index n = log.q.cols();
  const bool checked = target.lower.size() == static_cast<std::size_t>(n) && target.upper.size() == target.lower.size();
  const auto margin_of = [&](Eigen::Index j) {
    const double lo = target.lower[static_cast<std::size_t>(j)], hi = target.upper[static_cast<std::size_t>(j)];
    const bool prismatic = !target.prismatic.empty() && target.prismatic[static_cast<std::size_t>(j)];
    return std::max(prismatic ? kPrismaticMargin : kRevoluteMargin, 0.5 * (hi - lo));
  };
  const Worst worst = worst_sample(checked ? n : 0, log.samples(), 0, [&](Eigen::Index k, Eigen::Index j) {
    const double lo = target.lower[static_cast<std::size_t>(j)], hi = target.upper[static_cast<std::size_t>(j)];
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo))
      return -std::numeric_limits<double>::infinity();  // no limits to judge by
    return std::max(lo - log.q(k, j), log.q(k, j) - hi) - margin_of(j);
  });
  const Eigen::Index worst_row = worst.row, worst_joint = worst.joint;
  if (worst_row >= 0) {
    const std::size_t j = static_cast<std::size_t>(worst_joint);
    const bool prismatic = !target.prismatic.empty() && target.prismatic[j];
    const double lo = target.lower[j], hi = target.upper[j], q = log.q(worst_row, worst_joint);
    const double margin = margin_of(worst_joint);
    const std::string unit = prismatic ? "m" : "rad";
    const bool degrees = !prismatic && mapping.angle_unit == AngleUnit::deg;
    const std::string as_written = degrees ? fmt::format(" ({} as written, read as deg)", g(q * 180 / kPi)) : "";
    const std::string hint = prismatic ? "prismatic positions are read in m: is the file in mm?"
                             : degrees ? "is the angle unit right (--angle, units.angle)?"
                                       : "are the angles in deg, not rad (--angle deg, units.angle: deg)?";
    throw DataError(
        file, imported.lines[static_cast<std::size_t>(worst_row)],
        fmt::format("joint {} '{}' is at {} {}{}, far outside its limits [{}, {}] {} (by more than {} {}, "
                    "max({} {}, half its range)): {} {}",
                    worst_joint + 1, target.joints[j], g(q), unit, as_written, g(lo), g(hi), unit, g(margin), unit,
                    prismatic ? kPrismaticMargin : kRevoluteMargin, unit, hint, kOverride));
  }
}

// Torques: the sample farthest beyond kEffortFactor times its joint's effort limit.
void check_torques(const ImportedLog& imported, const ImportTarget& target) {
  const Log& log = imported.log;
  const std::string file = imported.input.string();
  const Eigen::Index n = log.q.cols();
  const Worst worst = worst_sample(log.tau.cols(), log.samples(), 1, [&](Eigen::Index k, Eigen::Index j) {
    const double effort =
        target.effort.size() == static_cast<std::size_t>(n) ? target.effort[static_cast<std::size_t>(j)] : 0.0;
    return std::abs(log.tau(k, j)) / (effort > 0 ? kEffortFactor * effort : kMaxTorque);
  });
  const Eigen::Index worst_row = worst.row, worst_joint = worst.joint;
  if (worst_row >= 0) {
    const std::size_t j = static_cast<std::size_t>(worst_joint);
    const double effort = target.effort.size() == static_cast<std::size_t>(n) ? target.effort[j] : 0.0;
    const bool prismatic = !target.prismatic.empty() && target.prismatic[j];
    const std::string unit = prismatic ? "N" : "N m";
    const std::string limit = effort > 0
                                  ? fmt::format("{} times its effort limit {} {}", kEffortFactor, g(effort), unit)
                                  : fmt::format("{} {}", g(kMaxTorque), unit);
    throw DataError(
        file, imported.lines[static_cast<std::size_t>(worst_row)],
        fmt::format("joint {} '{}' has a torque of {} {}, beyond {}: is the torque unit right (--torque-scale, "
                    "units.torque_scale: the factor from the file's unit to {})? {}",
                    worst_joint + 1, target.joints[j], g(log.tau(worst_row, worst_joint)), unit, limit, unit,
                    kOverride));
  }
}

// Radians declared as degrees: every revolute joint within +-2 pi as written and none moving
// 2 pi (6 "degrees") over the whole log, which no identification log does.
void check_angle_unit(const ImportedLog& imported, const ImportMapping& mapping, const ImportTarget& target) {
  const Log& log = imported.log;
  const std::string file = imported.input.string();
  const Eigen::Index n = log.q.cols();
  if (mapping.angle_unit == AngleUnit::deg && log.samples() > 1) {
    double largest = 0, widest = 0;
    int revolute = 0;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!target.prismatic.empty() && target.prismatic[static_cast<std::size_t>(j)]) continue;
      ++revolute;
      const double lo = log.q.col(j).minCoeff() * 180 / kPi, hi = log.q.col(j).maxCoeff() * 180 / kPi;
      largest = std::max({largest, std::abs(lo), std::abs(hi)});
      widest = std::max(widest, hi - lo);
    }
    if (revolute > 0 && largest <= 2 * kPi && widest < 2 * kPi)
      throw DataError(
          file, 0,
          fmt::format("the angles are declared in deg, but every joint stays within +-{} and moves at most {} as "
                      "written: these look like radians (--angle rad, units.angle: rad)? {}",
                      g(largest), g(widest), kOverride));
  }
}

// Time: a gap no recording has (24 h accepted): past kMaxGapSteps median steps and kMaxGap s;
// a median step outside a robot log's.
void check_time(const ImportedLog& imported, const ImportMapping& mapping) {
  const Log& log = imported.log;
  const std::string file = imported.input.string();
  const double median_step = log.meta.sample_time;
  for (Eigen::Index k = 1; k < log.samples(); ++k) {
    const double gap = log.time[k] - log.time[k - 1];
    if (gap > kMaxGap && gap > kMaxGapSteps * median_step)
      throw DataError(
          file, imported.lines[static_cast<std::size_t>(k)],
          fmt::format("a gap of {} s since line {} ({} times the median step {} s): a log is one recording; "
                      "split the file there, or {}",
                      g(gap), imported.lines[static_cast<std::size_t>(k - 1)], g(gap / median_step), g(median_step),
                      kOverride));
  }

  const double step = log.meta.sample_time;  // the median interval, to the us
  if (step < kMinStep || step > kMaxStep) {
    const TimeUnit u = mapping.time_unit;
    const std::string in_seconds =
        u == TimeUnit::s ? "" : fmt::format(" ({} s read as {})", g(step), detail::time_unit_name(u));
    throw DataError(file, 0,
                    fmt::format("the median time step is {} {} as written{}, outside the plausible [{} s, {} s] of a "
                                "robot's log: is the time unit right (--time-unit, units.time)? {}",
                                g(step * detail::time_divisor(u)), detail::time_unit_name(u), in_seconds, g(kMinStep),
                                g(kMaxStep), kOverride));
  }
}

// Velocity: its integral over the stamps against the position's change (velocity_agreement).
void check_velocity(const ImportedLog& imported) {
  const Log& log = imported.log;
  if (log.meta.velocity != Velocity::measured) return;
  const VelocityAgreement a = velocity_agreement(log);
  for (Eigen::Index j = 0; j < a.scale.size(); ++j) {
    const double k = a.scale(j);
    if (std::isnan(k) || (k >= kMinVelocityScale && k <= 1 / kMinVelocityScale && a.mismatch(j) <= kMaxMismatch))
      continue;
    throw DataError(
        imported.input.string(), 0,
        fmt::format("joint {} '{}': its position changes {} times what its logged velocity integrates to "
                    "over the stamps ({} windows of {} rows; {} of the change unexplained): is the velocity "
                    "in the position's unit per second (rad/s, m/s), the time unit right, and the velocity "
                    "column the joint's? {}",
                    j + 1, log.meta.joints[static_cast<std::size_t>(j)], g(k), a.windows, a.window, g(a.mismatch(j)),
                    kOverride));
  }
}

}  // namespace

VelocityAgreement velocity_agreement(const Log& log, double span) {
  const Eigen::Index n = log.q.cols(), rows = log.samples();
  VelocityAgreement a;
  // About `span` s of rows (5 to 100: a stale row at a window's end then moves its change by a
  // row in 5 at most, in 100 at 1 kHz); 20 windows at least in a short log.
  const double step = log.meta.sample_time > 0 ? log.meta.sample_time : 1e-3;
  const Eigen::Index wanted = std::clamp<Eigen::Index>(std::lround(span / step), 5, 100);
  a.window = static_cast<int>(std::max<Eigen::Index>(2, std::min<Eigen::Index>(wanted, rows / 20)));
  a.scale = a.mismatch = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  const Eigen::Index w = a.window, count = rows > w ? (rows - 1) / w : 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    double di = 0, ii = 0, dd = 0;
    int used = 0;
    Eigen::VectorXd D(count), I(count);
    for (Eigen::Index c = 0; c < count; ++c) {
      double integral = 0;
      for (Eigen::Index k = c * w; k < (c + 1) * w; ++k)
        integral += 0.5 * (log.qd(k, j) + log.qd(k + 1, j)) * (log.time(k + 1) - log.time(k));
      const double change = log.q((c + 1) * w, j) - log.q(c * w, j);
      if (!std::isfinite(change) || !std::isfinite(integral) || std::abs(change) > kMaxChange) continue;
      D(used) = change;
      I(used) = integral;
      di += change * integral;
      ii += integral * integral;
      dd += change * change;
      ++used;
    }
    a.windows = std::max(a.windows, used);
    if (used < kMinWindows || std::max(dd, ii) < used * kMinChange * kMinChange) continue;  // barely moves
    const double k = ii > 0 ? di / ii : std::numeric_limits<double>::infinity();
    a.scale(j) = k;
    a.mismatch(j) = ii > 0 ? std::sqrt((D.head(used) - k * I.head(used)).squaredNorm() / dd) : 1.0;
  }
  return a;
}

std::string detail::velocity_remark(const Log& log) {
  const VelocityAgreement a = velocity_agreement(log);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  std::string off;
  for (Eigen::Index j = 0; j < a.scale.size(); ++j) {
    const double k = a.scale(j);
    if (std::isnan(k)) continue;
    lo = std::min(lo, k);
    hi = std::max(hi, k);
    if (std::abs(k - 1) > 0.02)
      off += fmt::format("; joint {} '{}' {:.4f}: its stamps or its velocity are off", j + 1,
                         log.meta.joints[static_cast<std::size_t>(j)], k);
  }
  if (lo > hi) return "velocity against the stamps: no joint moves enough to compare";
  return fmt::format(
      "velocity against the stamps: each moving joint's position changes {:.4f}-{:.4f} times its logged velocity's "
      "integral ({} windows of {} rows; 1 when stamps, positions and velocity agree){}",
      lo, hi, a.windows, a.window, off);
}

void check_plausible(const ImportedLog& imported, const ImportMapping& mapping, const ImportTarget& target) {
  check_positions(imported, mapping, target);
  check_torques(imported, target);
  check_angle_unit(imported, mapping, target);
  check_time(imported, mapping);
  check_velocity(imported);
}

}  // namespace symoro::io
