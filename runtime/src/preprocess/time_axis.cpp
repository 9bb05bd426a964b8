#include "symoro/preprocess/time_axis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "symoro/error.hpp"

namespace symoro::preprocess {

namespace {

void validate_stamps(const Eigen::VectorXd& time, const std::string& source) {
  if (time.size() < 2) throw DataError(source, 0, fmt::format("{} time stamps; need at least 2", time.size()));
  for (Eigen::Index i = 0; i < time.size(); ++i) {
    if (!std::isfinite(time[i])) throw DataError(source, 0, fmt::format("time stamp of sample {} is not finite", i));
    if (i > 0 && !(time[i] > time[i - 1]))
      throw DataError(
          source, 0,
          fmt::format("time does not increase strictly at sample {} ({} s after {} s)", i, time[i], time[i - 1]));
  }
}

double median_interval(const Eigen::VectorXd& time) {
  std::vector<double> intervals(time.size() - 1);
  for (Eigen::Index i = 1; i < time.size(); ++i) intervals[i - 1] = time[i] - time[i - 1];
  auto middle = intervals.begin() + intervals.size() / 2;
  std::nth_element(intervals.begin(), middle, intervals.end());
  return *middle;
}

}  // namespace

StampAnalysis analyse_stamps(const Eigen::VectorXd& time, double period, double max_gap, const std::string& source) {
  if (!(period > 0) || !(max_gap > 0))
    throw std::invalid_argument("analyse_stamps: period and max_gap must be positive");
  validate_stamps(time, source);
  StampAnalysis a;
  a.t0 = time[0];
  a.period = period;
  a.median_interval = median_interval(time);
  if (std::abs(a.median_interval - period) > 0.1 * period)
    throw DataError(source, 0,
                    fmt::format("stamps are {:.6g} s apart (median) but the base period is {:.6g} "
                                "s; set the base period to the log's sample time",
                                a.median_interval, period));
  auto grid_index = [&](double t) { return std::lround((t - a.t0) / period); };

  StampPiece piece;
  piece.first_row = 0;
  piece.first_index = 0;
  long previous_index = 0;
  for (Eigen::Index i = 1; i < time.size(); ++i) {
    const double interval = time[i] - time[i - 1];
    const long index = grid_index(time[i]);
    a.max_deviation = std::max(a.max_deviation, std::abs(time[i] - (a.t0 + index * period)));
    if (std::abs(interval - period) > 0.1 * period) ++a.irregular_stamps;
    if (interval > max_gap) {
      piece.last_row = static_cast<int>(i - 1);
      piece.last_index = previous_index;
      a.pieces.push_back(piece);
      piece.first_row = static_cast<int>(i);
      piece.first_index = index;
    } else {
      if (interval > 1.5 * period) ++a.gaps_bridged;
      a.missing_samples += static_cast<int>(std::max(0L, index - previous_index - 1));
    }
    previous_index = index;
  }
  piece.last_row = static_cast<int>(time.size() - 1);
  piece.last_index = previous_index;
  a.pieces.push_back(piece);
  return a;
}

GridInterpolation grid_interpolation(const Eigen::VectorXd& time, const StampAnalysis& stamps,
                                     const StampPiece& piece) {
  if (piece.raw_samples() < 2) throw std::invalid_argument("grid_interpolation: a piece needs at least 2 stamps");
  GridInterpolation g;
  const int n = piece.grid_samples();
  g.left_row.resize(n);
  g.weight.resize(n);
  int left = piece.first_row;
  for (int k = 0; k < n; ++k) {
    const double t = stamps.t0 + static_cast<double>(piece.first_index + k) * stamps.period;
    // The bracketing interval; the end ones also serve the (at most half-period) extrapolation.
    while (left + 1 < piece.last_row && time[left + 1] <= t) ++left;
    g.left_row[k] = left;
    g.weight[k] = (t - time[left]) / (time[left + 1] - time[left]);
  }
  return g;
}

Channels GridInterpolation::apply(const Eigen::MatrixXd& signal) const {
  const Eigen::Index n = weight.size(), channels = signal.cols(), stride = signal.rows();
  Channels out(n, channels);
  // Sample by sample, each output row written once; the log's columns are read in step.
  const double* source = signal.data();
  double* target = out.data();
  for (Eigen::Index k = 0; k < n; ++k, target += channels) {
    const double w = weight[k];
    const double* left = source + left_row[k];
    for (Eigen::Index c = 0; c < channels; ++c) target[c] = (1 - w) * left[c * stride] + w * left[c * stride + 1];
  }
  return out;
}

}  // namespace symoro::preprocess
