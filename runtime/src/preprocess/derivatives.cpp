#include "symoro/preprocess/derivatives.hpp"

#include <stdexcept>

namespace symoro::preprocess {

Derivatives finite_differences(const Channels& x, double h, const std::vector<int>& rows) {
  const Eigen::Index n = x.rows();
  if (n < 4) throw std::invalid_argument("finite_differences: need at least 4 samples");
  Derivatives d;
  d.first.resize(static_cast<Eigen::Index>(rows.size()), x.cols());
  d.second.resize(static_cast<Eigen::Index>(rows.size()), x.cols());
  const double inv_2h = 1 / (2 * h), inv_h2 = 1 / (h * h);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Eigen::Index k = rows[i];
    if (k < 0 || k >= n) throw std::out_of_range("finite_differences: row outside the signal");
    const auto r = static_cast<Eigen::Index>(i);
    if (k == 0) {
      d.first.row(r) = (-3 * x.row(0) + 4 * x.row(1) - x.row(2)) * inv_2h;
      d.second.row(r) = (2 * x.row(0) - 5 * x.row(1) + 4 * x.row(2) - x.row(3)) * inv_h2;
    } else if (k == n - 1) {
      d.first.row(r) = (3 * x.row(k) - 4 * x.row(k - 1) + x.row(k - 2)) * inv_2h;
      d.second.row(r) = (2 * x.row(k) - 5 * x.row(k - 1) + 4 * x.row(k - 2) - x.row(k - 3)) * inv_h2;
    } else {
      d.first.row(r) = (x.row(k + 1) - x.row(k - 1)) * inv_2h;
      d.second.row(r) = (x.row(k + 1) - 2 * x.row(k) + x.row(k - 1)) * inv_h2;
    }
  }
  return d;
}

}  // namespace symoro::preprocess
