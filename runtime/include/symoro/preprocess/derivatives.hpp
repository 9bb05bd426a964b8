// Velocity and acceleration of a (filtered) signal on a uniform grid by second-order finite
// differences: central inside, one-sided at the ends. On the 1 kHz grid the truncation error
// (h^2/6 q''' and h^2/12 q'''') is far below what the filter leaves of encoder noise, so
// nothing more elaborate is needed; the filter, not the difference, sets the bandwidth.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "symoro/preprocess/channels.hpp"

namespace symoro::preprocess {

struct Derivatives {
  Eigen::MatrixXd first, second;  // rows.size() x signal columns
};

// d/dt and d2/dt2 of every channel of x (samples on a grid of step h, at least 4 rows), at the
// given rows only (the target grid keeps a fraction of the samples).
//   inside:    x' = (x[k+1] - x[k-1]) / 2h          x'' = (x[k+1] - 2 x[k] + x[k-1]) / h^2
//   first row: x' = (-3 x0 + 4 x1 - x2) / 2h        x'' = (2 x0 - 5 x1 + 4 x2 - x3) / h^2
//   last row:  mirrored (the 3-point one-sided x'' would be first order only).
Derivatives finite_differences(const Channels& x, double h, const std::vector<int>& rows);

}  // namespace symoro::preprocess
