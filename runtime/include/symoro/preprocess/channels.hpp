// Signals on the uniform grid: samples x channels, stored row-major so that the channels of one
// sample are contiguous. The filter's recursion is serial in time, so the independent channels
// are what its inner loop (and the vector unit) runs over, sample after sample.
#pragma once

#include <Eigen/Core>

namespace symoro::preprocess {

using Channels = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace symoro::preprocess
