#include "symoro/preprocess/resample.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "symoro/error.hpp"

namespace symoro::preprocess {

int target_stride(double interval, double base_period, const std::string& source, const std::string& period_origin) {
  const double ratio = interval / base_period;
  const double stride = std::round(ratio);
  if (!(interval > 0) || !std::isfinite(ratio) || stride < 1 || std::abs(ratio - stride) > 1e-9) {
    // The multiples around the interval asked for (the base period itself at least).
    const double below = std::isfinite(ratio) ? std::max(1.0, std::floor(ratio)) : 1.0;
    const double above = below + 1;
    throw DataError(source, 0,
                    fmt::format("interval {:.9g} s is not a positive integer multiple of the base "
                                "period {:.9g} s{}; nearest valid intervals: {:.9g} s and {:.9g} s",
                                interval, base_period, period_origin.empty() ? "" : " (" + period_origin + ")",
                                below * base_period, above * base_period));
  }
  return static_cast<int>(stride);
}

std::vector<int> target_rows(long first_index, int rows, int stride) {
  // The first multiple of stride at or after first_index (indices are >= 0: t0 is the first stamp).
  const long first_multiple = (first_index + stride - 1) / stride * stride;
  std::vector<int> kept;
  for (long index = first_multiple; index < first_index + rows; index += stride)
    kept.push_back(static_cast<int>(index - first_index));
  return kept;
}

}  // namespace symoro::preprocess
