// Zero-phase filtering: a cascade run forward and then backward over each column (|H|^2, no
// delay), as scipy.signal.sosfiltfilt(x, padtype="odd", padlen=padding), which it reproduces to
// rounding. The ends are extended by an odd reflection (2 x0 - x(k): value and slope continue
// across the end), and each pass starts at rest on its first input (sosfilt_zi * x[0]).
//
// What remains at the ends: the odd reflection flips the curvature, so the estimated qdd at an
// end tends to 0 whatever the true qdd, and the error decays with the filter's slowest time
// constant tau (measured: ~1.5 |qdd_end| at the end, /4 per tau; below the encoder noise after
// 5-6 tau, i.e. ~0.15 s at 15 Hz, ~0.5 s at 5 Hz). Logs that start and end at rest (qdd = 0)
// are unaffected; pieces split at a long gap in mid-motion are: preprocess() leaves the settling
// time at such ends out (edges.hpp).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/channels.hpp"

namespace symoro::preprocess {

// Padding, in samples, for a cascade: three slowest time constants, after which the start-up
// mismatch of a moving signal has decayed to e^-3 before the data begin. scipy's default,
// 3 * (2 * sections + 1) samples, is 15 samples for a 4th order: far shorter than the 28-sample
// time constant of a 15 Hz cutoff on a 1 kHz grid, so its start-up would leak into the data.
int zero_phase_padding(const std::vector<Biquad>& sections);

// Filters every channel of `signals` in place (the padding lives in two small buffers, not in
// a padded copy). Needs padding < rows (std::invalid_argument otherwise; callers check the
// length first and report it).
void filtfilt(const std::vector<Biquad>& sections, int padding, Channels& signals);

// filtfilt's output at a few rows of a signal fed one row at a time, without storing the signal:
// the forward pass runs as rows arrive; the backward pass, linear in its state (z <- A z + B u,
// y = C z + D u), is summed block by block between the wanted rows as the forward output comes,
// and swept back over the blocks at the end. Memory: (2 sections + 1) values per channel and
// wanted row, plus padding + 1 rows. Equal to filtfilt at those rows up to rounding.
class SampledZeroPhase {
 public:
  // `wanted`: rows of the signal (0 <= row < rows, any order, repeats allowed); padding < rows.
  SampledZeroPhase(const std::vector<Biquad>& sections, int padding, Eigen::Index rows, Eigen::Index channels,
                   const std::vector<Eigen::Index>& wanted);
  ~SampledZeroPhase();
  // The next row (rows in order 0, 1, ..., rows - 1; `channels` values).
  void push(const double* row);
  // After the last row: out(s, c) = filtfilt(signal)(wanted[s], c).
  void finish(Channels& out);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace symoro::preprocess
