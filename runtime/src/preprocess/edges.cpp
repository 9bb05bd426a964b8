#include "symoro/preprocess/edges.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace symoro::preprocess {

int settling_samples(const std::vector<Biquad>& sections) {
  return static_cast<int>(std::ceil(6 * slowest_time_constant(sections)));
}

Eigen::ArrayXd smallest_steps(const Eigen::MatrixXd& x) {
  Eigen::ArrayXd out = Eigen::ArrayXd::Constant(x.cols(), std::numeric_limits<double>::infinity());
  for (Eigen::Index j = 0; j < x.cols(); ++j)
    for (Eigen::Index k = 1; k < x.rows(); ++k) {
      const double step = std::abs(x(k, j) - x(k - 1, j));
      if (step > 0) out(j) = std::min(out(j), step);
    }
  return out.unaryExpr([](double v) { return std::isfinite(v) ? v : 0.0; });
}

bool moving_at_end(const Channels& q, int count, bool at_start, const Eigen::ArrayXd& quantum) {
  const Eigen::Index n = q.rows();
  if (count < 1 || count > n) throw std::invalid_argument("moving_at_end: needs 1 <= count <= rows");
  const auto end = at_start ? q.topRows(count) : q.bottomRows(count);
  for (Eigen::Index j = 0; j < q.cols(); ++j) {
    const double there = end.col(j).maxCoeff() - end.col(j).minCoeff();
    const double whole = q.col(j).maxCoeff() - q.col(j).minCoeff();
    // 1e-9 (rad or m): a channel without steps (a reference, a simulated hold) interpolated
    // between jittered stamps differs from itself by a rounding, which is no motion.
    if (there > std::max({4 * quantum(j), 1e-3 * whole, 1e-9})) return true;
  }
  return false;
}

}  // namespace symoro::preprocess
