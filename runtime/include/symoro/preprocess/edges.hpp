// The zero-phase filter's settling time at a log's own ends (issue 41). The odd reflection that
// pads each end (zero_phase.hpp) continues value and slope but flips the curvature, so where the
// arm still accelerates at an end the estimated qdd is wrong there, by about |qdd_end| or more,
// decaying with the filter's slowest time constant. A log cut anywhere in a motion (a
// controller's log, a piece split at a long gap; a run's window is filtered as its whole file)
// has such ends; a log that starts and ends at rest has none. preprocess() leaves the target
// samples within the settling time of a moving end out of what it returns and counts them
// (Report::edge_samples).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/channels.hpp"

namespace symoro::preprocess {

// Samples of the cascade's settling at an end: six slowest time constants (0.17 s at 15 Hz on a
// 1 kHz grid, 0.25 s at 10 Hz). What remains of the end's error there was measured at 1.1e-3 of
// the motion's largest acceleration (test_preprocess.cpp, PreprocessEdges).
int settling_samples(const std::vector<Biquad>& sections);

// The smallest nonzero step between two consecutive rows of each column of x: an encoder's
// quantum on a quantized log, ~0 on a log of floats.
Eigen::ArrayXd smallest_steps(const Eigen::MatrixXd& x);

// Whether the arm moves within `count` rows of one end of q (unfiltered, on the grid; the first
// rows when at_start, else the last): some joint's q spans more there than four of its quanta
// (an encoder toggling at rest spans one or two) and 1e-3 of its span over the whole of q (noise
// on a log of floats), and 1e-9 (a channel without steps, interpolated, differs from itself by a
// rounding). Moving includes a reversal (qd = 0, qdd != 0): it spans qdd t^2 / 2.
bool moving_at_end(const Channels& q, int count, bool at_start, const Eigen::ArrayXd& quantum);

}  // namespace symoro::preprocess
