// From a raw log to regression-ready samples (paper, Sec. V-B): time-axis correction of
// irregular stamps, zero-phase anti-alias filtering, velocity and acceleration estimation,
// and resampling to a target interval keeping only the samples on the target grid.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/io/log.hpp"

namespace symoro::preprocess {

struct Options {
  // s, the uniform grid of the corrected time axis. 0: the log's sidecar sample_time, or when
  // it has none its median stamp interval rounded to the microsecond; > 0 forces a period.
  double base_period = 0;
  // Gaps (dropped samples) up to this length are bridged by interpolation; longer gaps split
  // the log into separately processed pieces. Both are counted in the Report.
  double max_gap = 0.01;  // s (bridging error grows as gap^3: 0.08 rad/s^2 of qdd at 10 ms)
  int filter_order = 4;   // Butterworth order, applied forward and backward (zero phase)
  // One low-pass is applied to q and tau alike (so that the regressor and the torque see the
  // same filter): cutoff = min(derivative_cutoff, anti_alias_fraction * target Nyquist).
  double derivative_cutoff = 15.0;  // Hz
  double anti_alias_fraction = 0.8;
  // Rows whose q, qd and tau repeat the previous row bit for bit (qd compared only when it
  // was measured) are the logger reading one state twice: their stamp is not the state's
  // instant. They are left out as missing samples (bridged, or splitting the log when their
  // run is longer than max_gap). A repeat with every measured qd exactly 0 is the arm at rest,
  // not a stale read, and stays.
  bool drop_stale = true;
  // qd from the log's qd (through the same interpolation and filter as q) and qdd from its
  // differences, instead of both from q. DataError when the log's velocity was differentiated
  // at import (no measurement to use).
  bool use_logged_velocity = false;
  // s: the logged torque lags the torque acting on the links by this much (an actuation delay
  // dynid diagnose named: the servo reports the current it was commanded, which acts later).
  // The torque channel is read this much later (tau(t) := tau_logged(t + delay), on the
  // filtered grid, linear between grid points) so that it lines up with the motion. 0: none.
  double torque_delay = 0;
  // false: the torque is only brought onto the grid (interpolated between its stamps), not
  // low-passed: the raw measured torque, against which a model is scored (study/raw_torque.hpp).
  bool filter_torque = true;
  // Leave out the target samples within the filter's settling time of an end where the arm
  // moves (edges.hpp; counted in Report::edge_samples). false: keep them, transients and all.
  bool trim_settling = true;
};

// The base period preprocess() uses for `log`: options.base_period when positive, else the
// sidecar's sample_time, else the median stamp interval rounded to 1 us.
double base_period(const io::Log& log, const Options& options);

struct Report {
  int raw_samples = 0;
  double base_period = 0;          // s, the grid used (see base_period())
  int stale_rows = 0;              // repeated rows left out (Options::drop_stale)
  int irregular_stamps = 0;        // intervals deviating from base_period by more than 10 %
  int gaps_bridged = 0;            // gaps longer than 1.5 base periods and up to max_gap
  int missing_samples = 0;         // base-grid samples filled in across bridged gaps
  int pieces = 0;                  // independent pieces after splitting at long gaps
  double max_stamp_deviation = 0;  // s, largest distance of a stamp from its base-grid point
  // Pieces shorter than the filter's edge padding cannot be filtered; they are left out and
  // counted here (the log as a whole is rejected when no piece is long enough).
  int dropped_pieces = 0;
  int dropped_samples = 0;  // raw samples in the dropped pieces
  double cutoff = 0;        // Hz, the low-pass actually used
  // Target samples within the filter's settling time (settling_seconds) of a piece's end where
  // the arm moves, left out (edges.hpp), and how many such ends there were.
  int edge_samples = 0;
  int moving_ends = 0;
  double settling_seconds = 0;
  // A window of a longer file (io::Log::file: a dataset run's window): the file's rows around
  // it that were filtered through and not returned. 0 for a whole log.
  int context_rows = 0;
  int kept_samples = 0;         // target-grid samples returned
  std::string summary() const;  // one line for logs and reports
};

// Regression-ready samples at one interval: rows are samples on the target grid.
struct Samples {
  double interval = 0;              // s
  Eigen::VectorXd time;             // s, multiples of `interval` from the log's first stamp
  Eigen::MatrixXd q, qd, qdd, tau;  // samples x joints
  std::vector<int> piece;           // which piece of the log each sample came from
  Report report;
};

// A log cut from a longer file (io::Log::file, io::read_run_log) is filtered as that whole file,
// and only the samples within its own first and last stamps are returned: a window cut in
// mid-motion has no filter edge where it was cut, and its samples are those of the uncut file.
// Throws DataError when the log cannot give samples at this interval (too short, interval
// not a multiple of the base period: the message lists the nearest valid ones) or is inconsistent: time not strictly increasing, a value not
// finite, q and tau of different shapes, stamps whose median interval is not base_period within
// 10 %. The error names meta.trajectory (or "log") with line 0. Options outside their ranges
// throw std::invalid_argument. Stages: preprocess/time_axis.hpp, butterworth.hpp,
// zero_phase.hpp, derivatives.hpp, resample.hpp.
Samples preprocess(const io::Log& log, double interval, const Options& options = {});

// The paper's four intervals.
inline const std::vector<double>& paper_intervals() {
  static const std::vector<double> v{0.010, 0.020, 0.040, 0.080};
  return v;
}

}  // namespace symoro::preprocess
