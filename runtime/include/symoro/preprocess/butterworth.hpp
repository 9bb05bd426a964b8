// Digital Butterworth low-pass as cascaded second-order sections (SOS): the analog prototype's
// poles mapped by the bilinear transform with the cutoff prewarped, so that the digital filter
// has exactly |H|^2 = 1 / (1 + (tan(w/2) / tan(wc/2))^(2N)). Sections instead of one
// transfer-function polynomial because at cutoffs of a few hertz on a 1 kHz grid the poles
// crowd near z = 1 and a high-order polynomial loses them to rounding.
#pragma once

#include <vector>

namespace symoro::preprocess {

// y = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2) u. A first-order section has
// b2 = a2 = 0.
struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
  double dc_gain() const { return (b0 + b1 + b2) / (1 + a1 + a2); }
};

// Order `order` >= 1, cutoff (-3 dB) `cutoff_hz` in (0, sample_rate_hz / 2). Each section has
// unit DC gain (zeros at z = -1); sections are ordered by increasing pole radius, the most
// resonant last, as in scipy's zpk2sos. Throws std::invalid_argument on a bad specification.
std::vector<Biquad> butterworth_lowpass(int order, double cutoff_hz, double sample_rate_hz);

// Time constant of the slowest-decaying pole of a cascade, in samples: -1 / ln(max |pole|).
// The edge padding of zero-phase filtering is a multiple of it.
double slowest_time_constant(const std::vector<Biquad>& sections);

}  // namespace symoro::preprocess
