// Time-axis correction: logged stamps (the actual sample instants of a nominally periodic
// control loop, with jitter and dropped rows) mapped onto the uniform grid t0 + n * period,
// n counted from the log's first stamp t0. Short gaps are bridged; longer ones split the log
// into pieces that are filtered separately (a filter run across a long hole would invent data).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/preprocess/channels.hpp"

namespace symoro::preprocess {

// A run of stamps without a gap longer than max_gap. Every stamp belongs to its nearest grid
// point; the piece covers the grid points from its first stamp's to its last stamp's.
struct StampPiece {
  int first_row = 0, last_row = 0;       // raw rows, inclusive
  long first_index = 0, last_index = 0;  // grid indices, inclusive
  int raw_samples() const { return last_row - first_row + 1; }
  int grid_samples() const { return static_cast<int>(last_index - first_index + 1); }
};

struct StampAnalysis {
  double t0 = 0;      // s, the first stamp: grid index 0
  double period = 0;  // s
  std::vector<StampPiece> pieces;
  int irregular_stamps = 0;    // intervals deviating from period by more than 10 % (gaps included)
  int gaps_bridged = 0;        // intervals longer than 1.5 periods and up to max_gap
  int missing_samples = 0;     // grid points inside bridged gaps that no stamp maps to
  double max_deviation = 0;    // s, largest distance of a stamp from its grid point
  double median_interval = 0;  // s
};

// Validates and segments the stamps. Throws DataError(source, 0, ...) when a stamp is not
// finite, time does not increase strictly, there are fewer than 2 stamps, or the median
// interval is more than 10 % off `period` (the grid would resample the log, not correct it).
StampAnalysis analyse_stamps(const Eigen::VectorXd& time, double period, double max_gap, const std::string& source);

// Linear interpolation of raw rows onto a piece's grid points: grid sample k is
// (1 - weight[k]) * row left_row[k] + weight[k] * row left_row[k] + 1.
//
// Linear rather than cubic: at 1 kHz its error is at most qdd * h^2 / 8 (1.25e-6 rad at
// 10 rad/s^2), a thousandth of the 1.5e-3 rad encoder step, and across a 20 ms bridged gap
// 5e-4 rad, still below one step; a cubic through quantized samples would overshoot the
// staircase instead. The jitter itself is removed exactly because the stamps are the true
// instants. What a bridge costs after the 15 Hz filter, grows as gap^3 (measured at
// qdd = 9 rad/s^2): qdd off by 0.01 rad/s^2 for a 5 ms gap, 0.08 for 10 ms, 0.6 for 20 ms
// (encoder noise alone: 0.27 rms); torque loses what it had above the cutoff, e.g. the
// 100 Hz backlash ripple, over the gap. The two end grid points may lie up to half a period outside the piece's stamps
// and are extrapolated from the end interval (error (s + s^2) / 2 * qdd * h^2 for a fraction s
// of a period, below the interior bound while s < 0.2, i.e. jitter under 200 us at 1 kHz).
struct GridInterpolation {
  std::vector<int> left_row;
  Eigen::VectorXd weight;
  // Every grid sample of the piece: grid_samples rows, the signal's columns.
  Channels apply(const Eigen::MatrixXd& signal) const;
};

// Needs a piece of at least 2 stamps.
GridInterpolation grid_interpolation(const Eigen::VectorXd& time, const StampAnalysis& stamps, const StampPiece& piece);

}  // namespace symoro::preprocess
