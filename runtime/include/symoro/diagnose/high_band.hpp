// The closed loop's high band, and the floor of it that a real arm has and its twin does not:
// what backlash_fit.hpp judges play against.
//
// The floor is read from the log itself, apart from the plant. The logged torque is the servo's
// current; the controller's law (the description's FF+PD, applied to the logged position,
// velocity and references, quantized as the servo is) gives the command behind it. What the law
// does not explain (current noise, the current loop's error, a different quantization) is
// measurement: it adds to the high band whatever the plant does, play or not. The encoders'
// noise does enter the loop: it is estimated per joint from the logged position's second
// differences in counts, against the logged motion smoothed and quantized again with a trial
// noise (quantization alone leaves only the motion's count transitions), and given to the twin.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "symoro/io/log.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::diagnose {

struct BacklashFitOptions {
  double band_hz = 40;    // the high band starts here (the low band ends at the stack's 5 Hz)
  double light_hz = 150;  // the 1 kHz preprocessing's low-pass (the band's top)
  int seeds = 3;          // simulations of the twin: the spread of the high-band rms
  double sigmas = 6;      // an excess must exceed this many spreads ...
  // ... and this fraction of the null's rms: the loop's chatter is heavy-tailed from run to
  // run (clean twin runs of V01: joint 2 at 0.76-0.79 N m for five seeds, 0.98 for another),
  // which the spread of a few seeds does not show.
  double relative = 0.5;
  double max_width = 0.1;     // rad (5.7 deg): the bisection's upper end
  int bisection_steps = 10;   // width resolution max_width / 2^steps
  std::uint64_t seed = 7919;  // of the simulations (any: they are not the data's)
  // A selected actuation delay shapes the loop's ringing in the high band far more finely than
  // the low band resolves it: it is refined first (golden section over +-delay_range of it,
  // matching the log of the high-band rms on every joint), so its ringing is not taken for play.
  double delay_range = 0.3;
  int delay_steps = 10;
};

// A log's torque above band_hz, rms per joint (N m): the log preprocessed at its own rate (a
// light_hz low-pass), less its zero-phase band_hz low-pass, over every piece.
Eigen::VectorXd high_band_rms(const io::Log& log, const BacklashFitOptions& options = {});

struct LoopFloor {
  Eigen::VectorXd rms;       // N m per joint: the high band of what the law does not explain
  Eigen::VectorXd law_rms;   // N m per joint: that residual over all frequencies
  int lag = 0;               // rows from the command to the logged torque that shows it
  double encoder_noise = 0;  // counts (std), the median over joints (for the report)
  Eigen::VectorXd encoder_noise_per_joint;
};

// The floor of a log (its reference columns needed) under the controller and servos of `c`.
// The lag (0, 1 or 2 rows) is the one whose residual is smallest. Throws DataError naming the
// log when it has no references or differs from the description in joints.
LoopFloor loop_floor(const io::Log& log, const twin::TwinConfig& c, const BacklashFitOptions& options = {});

}  // namespace symoro::diagnose
