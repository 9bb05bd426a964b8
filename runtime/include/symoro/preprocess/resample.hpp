// Resampling to a target interval by keeping only the base-grid samples that lie on the
// target grid t0 + m * interval (paper, Sec. V-B): no interpolation, and no phase-shifted
// reuse of the samples in between, which would add highly correlated rows to the regression.
#pragma once

#include <string>
#include <vector>

namespace symoro::preprocess {

// Base periods per target interval. Throws DataError(source, 0, ...) unless interval is a
// positive integer multiple of base_period within 1e-9 (relative to base_period); the message
// names the nearest valid intervals and, when given, where the period came from.
int target_stride(double interval, double base_period, const std::string& source,
                  const std::string& period_origin = "");

// Rows of a piece (its first row at grid index first_index, `rows` rows) whose grid index is a
// multiple of stride: the piece's samples on the target grid, in order.
std::vector<int> target_rows(long first_index, int rows, int stride);

}  // namespace symoro::preprocess
