#include "symoro/trajectory/sampled_reference.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "symoro/error.hpp"

namespace symoro::trajectory {

SampledReference sample(const Trajectory& trajectory, double period) {
  if (!(period > 0)) throw std::invalid_argument("sampled reference: the period must be positive");
  const int n = trajectory.joints();
  const int cycles = static_cast<int>(std::llround(trajectory.duration() / period)) + 1;
  SampledReference r;
  r.name = trajectory.name;
  r.period = period;
  r.q.resize(n, cycles);
  r.qd.resize(n, cycles);
  r.qdd.resize(n, cycles);
  Eigen::VectorXd q(n), qd(n), qdd(n);
  for (int k = 0; k < cycles; ++k) {
    trajectory.evaluate(k * period, q, qd, qdd);
    r.q.col(k) = q;
    r.qd.col(k) = qd;
    r.qdd.col(k) = qdd;
  }
  return r;
}

SampledReference sampled_reference(const io::Log& log, double period) {
  const std::string source = log.meta.trajectory.empty() ? "log" : log.meta.trajectory;
  if (!(period > 0)) throw std::invalid_argument("sampled reference: the period must be positive");
  if (!log.has_references())
    throw DataError(source, 0,
                    "the log has no reference columns (q_ref, qd_ref, qdd_ref): the closed loop cannot be simulated");
  const Eigen::Index rows = log.samples();
  if (rows < 2) throw DataError(source, 0, "a reference needs at least 2 rows");
  std::vector<double> steps(static_cast<std::size_t>(rows - 1));
  for (Eigen::Index i = 1; i < rows; ++i) steps[static_cast<std::size_t>(i - 1)] = log.time(i) - log.time(i - 1);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double median = steps[steps.size() / 2];
  if (!(std::abs(median - period) <= 0.1 * period))
    throw DataError(source, 0,
                    fmt::format("rows are {:.6g} s apart (median), the controller's period is {:.6g} s: the "
                                "log's references are not the controller's cycles",
                                median, period));
  // A controller steps through its references by cycle: each row belongs to its nearest cycle
  // (stamp jitter moves the stamp, not the reference); cycles without a row (a dropped read)
  // are interpolated linearly between their neighbours.
  const double t0 = log.time(0);
  const int cycles = static_cast<int>(std::llround((log.time(rows - 1) - t0) / period)) + 1;
  std::vector<Eigen::Index> row_of(static_cast<std::size_t>(cycles), -1);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const long k = std::lround((log.time(i) - t0) / period);
    if (k >= 0 && k < cycles && row_of[static_cast<std::size_t>(k)] < 0) row_of[static_cast<std::size_t>(k)] = i;
  }
  const Eigen::Index n = log.q_ref.cols();
  SampledReference r;
  r.name = log.meta.trajectory;
  r.period = period;
  r.q.resize(n, cycles);
  r.qd.resize(n, cycles);
  r.qdd.resize(n, cycles);
  int left = 0;  // the last cycle with a row (cycle 0 has row 0)
  for (int k = 0; k < cycles; ++k) {
    const Eigen::Index i = row_of[static_cast<std::size_t>(k)];
    if (i >= 0) {
      r.q.col(k) = log.q_ref.row(i).transpose();
      r.qd.col(k) = log.qd_ref.row(i).transpose();
      r.qdd.col(k) = log.qdd_ref.row(i).transpose();
      left = k;
      continue;
    }
    int right = k + 1;
    while (row_of[static_cast<std::size_t>(right)] < 0) ++right;  // the last cycle has the last row
    const Eigen::Index a = row_of[static_cast<std::size_t>(left)], b = row_of[static_cast<std::size_t>(right)];
    const double w = static_cast<double>(k - left) / (right - left);
    r.q.col(k) = ((1 - w) * log.q_ref.row(a) + w * log.q_ref.row(b)).transpose();
    r.qd.col(k) = ((1 - w) * log.qd_ref.row(a) + w * log.qd_ref.row(b)).transpose();
    r.qdd.col(k) = ((1 - w) * log.qdd_ref.row(a) + w * log.qdd_ref.row(b)).transpose();
  }
  return r;
}

}  // namespace symoro::trajectory
