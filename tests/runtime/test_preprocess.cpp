// Preprocessing from a raw 1 kHz log to regression-ready samples, checked against references
// that do not use the code under test: the bilinear Butterworth formula, exact derivatives of
// synthetic motions, and noise levels predicted from the encoder quantization through the
// filter's analytic response.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "symoro/error.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/derivatives.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/preprocess/resample.hpp"
#include "symoro/preprocess/time_axis.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace pp = symoro::preprocess;
using symoro::DataError;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kH = 0.001;                     // base period, s
constexpr double kEncoderStep = 2 * kPi / 4096;  // 12-bit encoder, rad
constexpr double kCurrentStep = 0.006;           // torque resolution, N m

// ---- References independent of the code under test -------------------------------------------

// |H(e^jw)|^2 of an order-n Butterworth designed by the prewarped bilinear transform; a
// zero-phase (forward-backward) run applies it once as a real, non-negative gain.
double bilinear_butterworth_power(double f, double cutoff, int order, double fs = 1 / kH) {
  const double ratio = std::tan(kPi * f / fs) / std::tan(kPi * cutoff / fs);
  return 1 / (1 + std::pow(ratio, 2 * order));
}

// H(e^jw) evaluated directly from the section coefficients.
std::complex<double> response(const std::vector<pp::Biquad>& sections, double w) {
  const std::complex<double> z1 = std::polar(1.0, -w), z2 = z1 * z1;
  std::complex<double> h = 1;
  for (const pp::Biquad& s : sections) h *= (s.b0 + s.b1 * z1 + s.b2 * z2) / (1.0 + s.a1 * z1 + s.a2 * z2);
  return h;
}

// Standard deviation of the m-th derivative estimate (m = 0, 1, 2) left by white noise of
// standard deviation sigma on the 1 kHz grid after zero-phase filtering (gain |H|^2, so power
// |H|^4) and the central difference (|sin(wh)/h|^2 for m = 1, |(2 - 2cos wh)/h^2|^2 for m = 2):
//   var = sigma^2 * 2/fs * integral_0^{fs/2} |H|^4 |D_m|^2 df   (Simpson's rule).
double filtered_noise_sigma(double sigma, double cutoff, int order, int m) {
  const int n = 20000;
  const double fs = 1 / kH, df = fs / 2 / n;
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    const double f = i * df, w = 2 * kPi * f * kH;
    const double h2 = bilinear_butterworth_power(f, cutoff, order);
    const double d = m == 0 ? 1 : m == 1 ? std::sin(w) / kH : (2 - 2 * std::cos(w)) / (kH * kH);
    const double weight = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    sum += weight * h2 * h2 * d * d;
  }
  return sigma * std::sqrt(2 / fs * sum * df / 3);
}

// Worst case of the same: the quantization error of a grid sample is at most step / 2 whatever
// its spectrum (slow motion turns it into a slow staircase that the white model misses), so the
// filtered m-th derivative errs by at most step / 2 * ||D_m h||_1, where h is the zero-phase
// impulse response h[n] = 1/pi integral_0^pi |H|^2 cos(w n) dw (Simpson; cos(w n) by the
// Chebyshev recurrence) and D_m the central difference. Returns ||h||_1, ||D_1 h||_1, ||D_2 h||_1.
// (scipy's sosfiltfilt impulse response gives 1.381, 84.39, 6457 at 15 Hz.)
std::array<double, 3> impulse_response_l1(double cutoff, int order, double tau_samples) {
  const int half = static_cast<int>(25 * tau_samples), intervals = 1 << 15;
  std::vector<double> h(half + 2, 0.0);  // h[0..half+1]; h[-n] = h[n]
  const double dw = kPi / intervals;
  for (int i = 0; i <= intervals; ++i) {
    const double w = i * dw;
    const double weight = ((i == 0 || i == intervals) ? 1 : (i % 2 ? 4 : 2)) * dw / 3 / kPi *
                          bilinear_butterworth_power(w / (2 * kPi * kH), cutoff, order);
    if (weight < 1e-300) continue;
    const double c1 = std::cos(w);
    double previous = c1, current = 1;  // cos(-w), cos(0)
    for (int n = 0; n <= half + 1; ++n) {
      h[n] += weight * current;
      const double next = 2 * c1 * current - previous;
      previous = current;
      current = next;
    }
  }
  const auto at = [&](int n) { return h[std::abs(n)]; };
  std::array<double, 3> l1{0, 0, 0};
  for (int n = -half; n <= half; ++n) {
    l1[0] += std::abs(at(n));
    l1[1] += std::abs(at(n + 1) - at(n - 1)) / (2 * kH);
    l1[2] += std::abs(at(n + 1) - 2 * at(n) + at(n - 1)) / (kH * kH);
  }
  return l1;
}

// Slowest time constant of the analog Butterworth, s: 1 / (wc sin(pi / 2N)).
double analog_time_constant(double cutoff, int order) { return 1 / (2 * kPi * cutoff * std::sin(kPi / (2 * order))); }

// ---- Synthetic motions with exact derivatives ------------------------------------------------

struct Sinusoid {
  double amplitude, frequency, phase;
};

// q(t) = offset + sum of sinusoids, or a polynomial; value and derivatives are exact, and
// `gain(f)` scales each sinusoid as a zero-phase filter would (the filtered reference).
struct Motion {
  double offset = 0;
  std::vector<Sinusoid> sinusoids;
  std::vector<double> polynomial;  // c0 + c1 t + c2 t^2 + ..., used when non-empty
  // derivative order 0, 1, 2 at t, each sinusoid scaled by gain(frequency)
  double eval(double t, int order, const std::function<double(double)>& gain = nullptr) const {
    double v = 0;
    if (!polynomial.empty()) {
      for (std::size_t i = order; i < polynomial.size(); ++i) {
        double falling = 1;
        for (int k = 0; k < order; ++k) falling *= static_cast<double>(i - k);
        v += polynomial[i] * falling * std::pow(t, static_cast<double>(i - order));
      }
      return v;
    }
    if (order == 0) v = offset;
    for (const Sinusoid& s : sinusoids) {
      const double w = 2 * kPi * s.frequency, g = gain ? gain(s.frequency) : 1.0;
      const double arg = w * t + s.phase;
      v += g * s.amplitude * (order == 0 ? std::sin(arg) : order == 1 ? w * std::cos(arg) : -w * w * std::sin(arg));
    }
    return v;
  }
};

// How the synthetic log is recorded.
struct Recording {
  double start = 3.0;      // s, the nominal first instant
  double duration = 20.0;  // s
  double jitter = 40e-6;   // s, stamps are k h + e_k, e_k uniform in [-jitter, jitter]
  std::set<int> dropped;   // nominal sample numbers that are missing from the log
  bool quantize = true;    // 12-bit q; tau quantized to 0.006 N m plus noise
  double backlash = 0.3;   // N m, amplitude of a 100 Hz oscillation on tau
  unsigned seed = 1;
};

// tau of joint j: a smooth torque the filter must keep (checked like q).
Motion torque_motion(int j) {
  Motion m;
  m.offset = 0.5 * j;
  m.sinusoids = {{1.5, 0.3 + 0.1 * j, 0.2}, {0.4, 1.7, 1.0 + j}};
  return m;
}

symoro::io::Log record(const std::vector<Motion>& joints, const Recording& r) {
  std::mt19937 rng(r.seed);
  std::uniform_real_distribution<double> jitter(-r.jitter, r.jitter);
  std::normal_distribution<double> torque_noise(0, 0.01);
  const int nominal = static_cast<int>(std::lround(r.duration / kH)) + 1;
  const int n = nominal - static_cast<int>(r.dropped.size());
  symoro::io::Log log;
  log.meta.trajectory = "synthetic";
  log.meta.sample_time = kH;
  const int dof = static_cast<int>(joints.size());
  log.time.resize(n);
  log.q.resize(n, dof);
  log.qd.resize(n, dof);
  log.tau.resize(n, dof);
  int row = 0;
  for (int k = 0; k < nominal; ++k) {
    const double e = jitter(rng);  // drawn for every instant, so drops do not shift the noise
    if (r.dropped.count(k)) continue;
    const double t = r.start + k * kH + e;
    log.time[row] = t;
    for (int j = 0; j < dof; ++j) {
      const double q = joints[j].eval(t - r.start, 0);
      log.q(row, j) = r.quantize ? kEncoderStep * std::round(q / kEncoderStep) : q;
      log.qd(row, j) = joints[j].eval(t - r.start, 1);
      double tau = torque_motion(j).eval(t - r.start, 0) + r.backlash * std::sin(2 * kPi * 100 * (t - r.start) + j);
      if (r.quantize) tau = kCurrentStep * std::round((tau + torque_noise(rng)) / kCurrentStep);
      log.tau(row, j) = tau;
    }
    ++row;
  }
  return log;
}

// Motions within the brief's ranges: sinusoids of 0.2-3 Hz, amplitudes 0.1-1 rad.
std::vector<Motion> sinusoid_motions(int dof) {
  std::vector<Motion> joints;
  for (int j = 0; j < dof; ++j) {
    Motion m;
    m.offset = 0.1 * j;
    m.sinusoids = {{1.0 - 0.1 * j, 0.2 + 0.05 * j, 0.3 * j}, {0.5, 1.0 + 0.1 * j, 1.0}, {0.1, 3.0, 2.0 - 0.2 * j}};
    joints.push_back(m);
  }
  return joints;
}

// Dropped rows like the arm's: single samples and runs of up to 4 (gaps of 2-5 ms).
std::set<int> typical_drops(int nominal, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> where(100, nominal - 100), length(1, 4);
  std::set<int> dropped;
  for (int i = 0; i < 20; ++i) {
    const int first = where(rng), count = length(rng);
    for (int k = 0; k < count; ++k) dropped.insert(first + k);
  }
  return dropped;
}

// Largest and RMS absolute error over a set of rows.
struct ErrorStats {
  double max = 0, rms = 0;
  int count = 0;
  void add(double e) {
    max = std::max(max, std::abs(e));
    rms += e * e;
    ++count;
  }
  double root_mean_square() const { return count ? std::sqrt(rms / count) : 0; }
};

}  // namespace

// ---- Butterworth design ------------------------------------------------------------------------

// The designed cascade against the analytic bilinear-transform magnitude. Both are exact
// expressions of the same filter, so they differ by rounding only: the sections' coefficients
// carry ~1e-16 relative error, amplified near z = 1 by the pole crowding at a low cutoff
// (1 / (1 - r) ~ 100 for 5 Hz at 1 kHz), so 1e-10 relative is a generous bound that any design
// error (wrong prewarp: ~1e-4 at 15 Hz; wrong pole angle or pairing: O(1)) would break.
TEST(PreprocessButterworth, MagnitudeMatchesBilinearFormula) {
  const double fs = 1 / kH;
  for (int order : {1, 2, 3, 4, 5, 6, 8}) {
    for (double cutoff : {5.0, 6.25, 15.0, 100.0, 350.0}) {
      const auto sections = pp::butterworth_lowpass(order, cutoff, fs);
      EXPECT_EQ(static_cast<int>(sections.size()), (order + 1) / 2);
      for (double f : {0.0, 0.5, 1.0, 3.0, cutoff / 2, cutoff, 1.5 * cutoff, 2 * cutoff, 100.0, 300.0, 499.0}) {
        if (f >= fs / 2) continue;
        const double expected = bilinear_butterworth_power(f, cutoff, order, fs);
        const double actual = std::norm(response(sections, 2 * kPi * f / fs));
        if (expected > 1e-20)
          EXPECT_NEAR(actual / expected, 1.0, 1e-10) << "order " << order << " cutoff " << cutoff << " f " << f;
        else
          EXPECT_LT(actual, 1e-18);
      }
      // -3 dB at the cutoff exactly (the prewarp), unit DC gain per section, stable poles.
      EXPECT_NEAR(std::norm(response(sections, 2 * kPi * cutoff / fs)), 0.5, 1e-12);
      for (const pp::Biquad& s : sections) {
        EXPECT_NEAR(s.dc_gain(), 1.0, 1e-13);
        EXPECT_LT(std::abs(s.a2), 1.0);
      }
      EXPECT_GT(pp::slowest_time_constant(sections), 0.0);
    }
  }
}

// The slowest pole of an order-N analog Butterworth has real part -wc sin(pi/2N): for N = 4 at
// 15 Hz, tau = 1 / (2 pi 15 sin(22.5 deg)) = 27.7 ms, i.e. 27.7 samples; the bilinear map
// shifts this by < 1 % at this cutoff.
TEST(PreprocessButterworth, TimeConstantAndPadding) {
  const auto sections = pp::butterworth_lowpass(4, 15.0, 1 / kH);
  const double analog = 1 / (2 * kPi * 15.0 * std::sin(kPi / 8)) / kH;
  EXPECT_NEAR(pp::slowest_time_constant(sections) / analog, 1.0, 0.01);
  EXPECT_EQ(pp::zero_phase_padding(sections), static_cast<int>(std::ceil(3 * pp::slowest_time_constant(sections))));
  EXPECT_THROW(pp::butterworth_lowpass(4, 500.0, 1000.0), std::invalid_argument);
  EXPECT_THROW(pp::butterworth_lowpass(0, 15.0, 1000.0), std::invalid_argument);
}

// ---- Zero-phase filtering ----------------------------------------------------------------------

// A 2 Hz sine through forward-backward filtering, fitted as a sin + b cos over the interior
// (beyond two paddings from either end): the phase atan2(b, a) must vanish and the amplitude
// equal |H|^2. One forward pass alone would lag by arg H(2 Hz), computed here to show that the
// check is sensitive. Bounds: the start-up transient (about slope * group delay, i.e. 0.35 of
// the amplitude here) has decayed by e^-(3+6) = 1e-4 before the interior, and the fit averages
// it over 3.7 s; 1e-6 rad and 1e-6 in amplitude leave a margin of ~20 over what was measured
// (phase 4e-8, amplitude 5e-8).
TEST(PreprocessZeroPhase, SinusoidIsNotShiftedAndScaledByPowerResponse) {
  const double f = 2.0, cutoff = 15.0;
  const auto sections = pp::butterworth_lowpass(4, cutoff, 1 / kH);
  const int pad = pp::zero_phase_padding(sections);
  const int n = 4000;
  Eigen::MatrixXd x(n, 2);
  for (int k = 0; k < n; ++k) {
    x(k, 0) = std::sin(2 * kPi * f * k * kH);
    x(k, 1) = 0.3 + 0.7 * std::sin(2 * kPi * f * k * kH);  // an offset must not matter
  }
  pp::Channels y = x;
  pp::filtfilt(sections, pad, y);
  const int first = 2 * pad, last = n - 2 * pad;
  Eigen::MatrixXd basis(last - first, 3);
  for (int k = first; k < last; ++k)
    basis.row(k - first) << std::sin(2 * kPi * f * k * kH), std::cos(2 * kPi * f * k * kH), 1;
  const double gain = bilinear_butterworth_power(f, cutoff, 4);
  for (int c = 0; c < 2; ++c) {
    const Eigen::Vector3d fit = basis.colPivHouseholderQr().solve(y.col(c).segment(first, last - first));
    const double amplitude = c == 0 ? 1.0 : 0.7;
    EXPECT_NEAR(std::atan2(fit[1], fit[0]), 0.0, 1e-6);
    EXPECT_NEAR(std::hypot(fit[0], fit[1]) / amplitude, gain, 1e-6);
    EXPECT_NEAR(fit[2], c == 0 ? 0.0 : 0.3, 1e-6);
  }
  const double one_pass_lag = -std::arg(response(sections, 2 * kPi * f * kH));
  EXPECT_GT(one_pass_lag, 0.3);  // 0.349 rad: what a missing backward pass would leave
}

// Against scipy 1.10.1 itself, the behaviour this filter reproduces (odd padding, sosfilt_zi
// start, forward then backward), values computed offline with
//   sos = scipy.signal.butter(4, 15, fs=1000, output="sos"); k = numpy.arange(300.0)
//   x = numpy.sin(0.01 * k) + 0.5 * numpy.cos(0.037 * k) + 1e-5 * k * k
//   y = scipy.signal.sosfiltfilt(sos, x, padtype="odd", padlen=84)
// scipy keeps the gain in its first section where ours has unit DC gain in each; the two
// cascades agree to rounding (~1e-15 relative per step over ~470 steps), hence 1e-12. The ends
// are included: they check the padding and the initial states, not only the response.
TEST(PreprocessZeroPhase, MatchesScipySosfiltfilt) {
  const auto sections = pp::butterworth_lowpass(4, 15.0, 1000.0);
  ASSERT_EQ(pp::zero_phase_padding(sections), 84);
  pp::Channels x(300, 1);
  for (int k = 0; k < 300; ++k) x(k, 0) = std::sin(0.01 * k) + 0.5 * std::cos(0.037 * k) + 1e-5 * k * k;
  pp::filtfilt(sections, 84, x);
  const std::vector<std::pair<int, double>> scipy{
      {0, 0.4984241762171907},   {1, 0.5034544159119969},   {2, 0.5084626338149228},
      {42, 0.44214854957720573}, {83, 0.30615814292747157}, {150, 1.5936497479053886},
      {216, 1.2292169120482141}, {298, 1.0709760160040094}, {299, 1.08623295371425}};
  for (const auto& [k, expected] : scipy) EXPECT_NEAR(x(k, 0), expected, 1e-12) << k;
}

// A constant passes unchanged up to the ends (the steady-state start), and a signal no longer
// than the padding is refused.
TEST(PreprocessZeroPhase, ConstantPassesUnchangedAndShortSignalIsRefused) {
  const auto sections = pp::butterworth_lowpass(4, 5.0, 1 / kH);
  const int pad = pp::zero_phase_padding(sections);
  Eigen::MatrixXd x = Eigen::MatrixXd::Constant(600, 2, 1.25);
  x.col(1).setConstant(-0.5);
  pp::Channels y = x;
  pp::filtfilt(sections, pad, y);
  // Rounding through ~1100 recursive steps of a cascade with poles at r = 0.99 (measured
  // 1.7e-13).
  EXPECT_LT((y - x).cwiseAbs().maxCoeff(), 1e-12);
  pp::Channels too_short = pp::Channels::Zero(pad, 1);
  EXPECT_THROW(pp::filtfilt(sections, pad, too_short), std::invalid_argument);
}

// SampledZeroPhase (rows fed one at a time, only some rows kept) against filtfilt on the whole
// signal: the same numbers up to rounding, for wanted rows at the very ends, unsorted, repeated
// and irregularly spaced, with and without padding.
TEST(PreprocessZeroPhase, SampledStreamMatchesFiltfiltAtTheWantedRows) {
  const auto sections = pp::butterworth_lowpass(4, 10.0, 1000.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (const int pad : {pp::zero_phase_padding(sections), 0, 5}) {
    SCOPED_TRACE(pad);
    const Eigen::Index rows = 1500, channels = 3;
    pp::Channels x(rows, channels);
    for (Eigen::Index k = 0; k < rows; ++k)
      x.row(k) << std::sin(0.01 * k) + 0.1 * normal(rng), 1e-6 * k * k, 0.3 * normal(rng);
    pp::Channels whole = x;
    pp::filtfilt(sections, pad, whole);
    std::vector<Eigen::Index> wanted{rows - 1, 0, 40, 80, 40, 121, 1000, 1001, 1499 - pad};
    pp::SampledZeroPhase stream(sections, pad, rows, channels, wanted);
    for (Eigen::Index k = 0; k < rows; ++k) stream.push(x.row(k).data());
    pp::Channels sampled;
    stream.finish(sampled);
    ASSERT_EQ(sampled.rows(), static_cast<Eigen::Index>(wanted.size()));
    for (std::size_t w = 0; w < wanted.size(); ++w)
      for (Eigen::Index c = 0; c < channels; ++c)
        EXPECT_NEAR(sampled(static_cast<Eigen::Index>(w), c), whole(wanted[w], c),
                    1e-12 * (1 + whole.col(c).cwiseAbs().maxCoeff()))
            << wanted[w] << ", " << c;
  }
}

// ---- Finite differences ------------------------------------------------------------------------

// The formulas' error terms, exactly, on polynomials (Taylor): for x' the central difference
// errs by +h^2/6 x''' and the one-sided ones by -h^2/3 x'''; every x'' formula is exact up to
// cubics (its error has x''''). So on x = 1 + t - 4 t^2 + 30 t^3 (x''' = 180) the first
// derivative must be off by exactly 3e-5 inside and -6e-5 at the ends, and the rest exact.
TEST(PreprocessDerivatives, ErrorTermsOnPolynomials) {
  const int n = 50;
  pp::Channels x(n, 2);
  for (int k = 0; k < n; ++k) {
    const double t = k * kH;
    x.row(k) << 0.3 - 2 * t + 5 * t * t, 1 + t - 4 * t * t + 30 * t * t * t;
  }
  std::vector<int> rows(n);
  for (int k = 0; k < n; ++k) rows[k] = k;
  const pp::Derivatives d = pp::finite_differences(x, kH, rows);
  for (int k = 0; k < n; ++k) {
    const double t = k * kH;
    // Rounding: differences of O(1) values divided by h (1e-16 / 1e-3) and h^2 (1e-16 / 1e-6),
    // with margin.
    EXPECT_NEAR(d.first(k, 0), -2 + 10 * t, 1e-11);
    EXPECT_NEAR(d.second(k, 0), 10, 1e-8);
    EXPECT_NEAR(d.second(k, 1), -8 + 180 * t, 1e-8);
    const double term = (k == 0 || k == n - 1) ? -kH * kH / 3 * 180 : kH * kH / 6 * 180;
    EXPECT_NEAR(d.first(k, 1), 1 - 8 * t + 90 * t * t + term, 1e-11);
  }
  const pp::Derivatives some = pp::finite_differences(x, kH, {7, 0, 49});
  EXPECT_EQ(some.first.rows(), 3);
  EXPECT_EQ(some.first(0, 0), d.first(7, 0));
  EXPECT_THROW(pp::finite_differences(x.topRows(3), kH, {0}), std::invalid_argument);
}

// ---- Time axis ---------------------------------------------------------------------------------

// Jitter alone (no quantization): linear interpolation between the true instants is bounded by
// qdd_max * dt_max^2 / 8 with dt_max the longest stamp interval (1.08 ms with 40 us jitter);
// the end grid points are extrapolated by at most the jitter (s = 0.04 of a period), whose
// bound (s + s^2) / 2 * qdd_max * h^2 is smaller. Keeping a raw sample at its nominal instant
// instead would err by qd * jitter ~ 6 rad/s * 40 us = 2.4e-4 rad, fifty times this bound.
TEST(PreprocessTimeAxis, JitterAloneIsCorrectedWithinTheInterpolationBound) {
  const std::vector<Motion> joints = sinusoid_motions(3);
  Recording r;
  r.quantize = false;
  r.duration = 5;
  const symoro::io::Log log = record(joints, r);
  const pp::StampAnalysis stamps = pp::analyse_stamps(log.time, kH, 0.02, "synthetic");
  ASSERT_EQ(stamps.pieces.size(), 1u);
  EXPECT_EQ(stamps.pieces[0].grid_samples(), log.samples());
  EXPECT_EQ(stamps.irregular_stamps, 0);  // 80 us at most, under 10 % of 1 ms
  EXPECT_LE(stamps.max_deviation, 2 * r.jitter);
  const double dt_max = (log.time.tail(log.samples() - 1) - log.time.head(log.samples() - 1)).maxCoeff();
  const pp::GridInterpolation g = pp::grid_interpolation(log.time, stamps, stamps.pieces[0]);
  const pp::Channels grid = g.apply(log.q);
  ASSERT_EQ(grid.rows(), stamps.pieces[0].grid_samples());
  for (int j = 0; j < 3; ++j) {
    double qdd_max = 0, worst = 0;
    for (int k = 0; k < grid.rows(); ++k) {
      // t - start: the grid is t0 + k h and t0 = start + e_0.
      const double t = stamps.t0 + k * kH - r.start;
      qdd_max = std::max(qdd_max, std::abs(joints[j].eval(t, 2)));
      worst = std::max(worst, std::abs(grid(k, j) - joints[j].eval(t, 0)));
    }
    const double bound = qdd_max * dt_max * dt_max / 8;
    EXPECT_LT(worst, bound) << "joint " << j;
    std::printf("  jitter only, joint %d: max interpolation error %.3g rad, bound %.3g rad\n", j, worst, bound);
  }
}

TEST(PreprocessTimeAxis, ShortGapIsBridgedAndLongGapSplits) {
  const std::vector<Motion> joints = sinusoid_motions(2);
  Recording r;
  r.duration = 3;
  for (int k = 1000; k < 1003; ++k) r.dropped.insert(k);  // 4 ms interval: bridged
  for (int k = 2000; k < 2049; ++k) r.dropped.insert(k);  // 50 ms interval: split
  const symoro::io::Log log = record(joints, r);
  const pp::StampAnalysis stamps = pp::analyse_stamps(log.time, kH, 0.02, "synthetic");
  EXPECT_EQ(stamps.gaps_bridged, 1);
  EXPECT_EQ(stamps.missing_samples, 3);
  EXPECT_EQ(stamps.irregular_stamps, 2);  // the two gaps; the jitter stays under 10 %
  ASSERT_EQ(stamps.pieces.size(), 2u);
  EXPECT_EQ(stamps.pieces[0].first_index, 0);
  EXPECT_EQ(stamps.pieces[0].last_index, 1999);
  EXPECT_EQ(stamps.pieces[0].raw_samples(), 1997);
  EXPECT_EQ(stamps.pieces[1].first_index, 2049);
  EXPECT_EQ(stamps.pieces[1].last_index, 3000);

  // Every target sample, the settling time at the pieces' moving ends kept (checked below).
  pp::Options every;
  every.trim_settling = false;
  const pp::Samples s = pp::preprocess(log, 0.020, every);
  EXPECT_EQ(s.report.raw_samples, log.samples());
  EXPECT_EQ(s.report.gaps_bridged, 1);
  EXPECT_EQ(s.report.missing_samples, 3);
  EXPECT_EQ(s.report.pieces, 2);
  EXPECT_EQ(s.report.dropped_pieces, 0);
  // Grid indices 0..1999 and 2049..3000, target multiples of 20: 0..1980 (100) and 2060..3000 (48).
  EXPECT_EQ(s.report.kept_samples, 148);
  ASSERT_EQ(static_cast<int>(s.piece.size()), 148);
  EXPECT_EQ(std::count(s.piece.begin(), s.piece.end(), 0), 100);
  EXPECT_EQ(std::count(s.piece.begin(), s.piece.end(), 1), 48);
  EXPECT_NEAR(s.time[100] - log.time[0], 2.060, 1e-12);
  // By default the four ends, all in motion (the split too), lose their settling time (0.167 s:
  // target indices 0..160 and 1840..1980 of the first piece, 2060..2200 and 2840..3000 of the
  // second, 9 + 8 + 8 + 9 samples).
  const pp::Samples trimmed = pp::preprocess(log, 0.020);
  EXPECT_EQ(trimmed.report.moving_ends, 4);
  EXPECT_EQ(trimmed.report.edge_samples, 34);
  EXPECT_EQ(trimmed.report.kept_samples, 148 - 34);
}

// A fragment shorter than the filter's padding is left out and counted, not silently lost.
TEST(PreprocessTimeAxis, FragmentTooShortForTheFilterIsDroppedAndCounted) {
  const std::vector<Motion> joints = sinusoid_motions(1);
  Recording r;
  r.duration = 2;
  for (int k = 1000; k < 1100; ++k) r.dropped.insert(k);  // split
  for (int k = 1130; k < 1200; ++k) r.dropped.insert(k);  // leaves rows 1100..1129 alone
  const symoro::io::Log log = record(joints, r);
  const pp::Samples s = pp::preprocess(log, 0.010);
  EXPECT_EQ(s.report.pieces, 3);
  EXPECT_EQ(s.report.dropped_pieces, 1);
  EXPECT_EQ(s.report.dropped_samples, 30);
  for (int p : s.piece) EXPECT_NE(p, 1);
  EXPECT_NE(s.report.summary().find("dropped with 30 samples"), std::string::npos);
}

// ---- Resampling --------------------------------------------------------------------------------

TEST(PreprocessResample, KeepsExactlyTheTargetGridSamples) {
  EXPECT_EQ(pp::target_stride(0.010, 0.001, "x"), 10);
  EXPECT_EQ(pp::target_stride(0.080, 0.001, "x"), 80);
  EXPECT_EQ(pp::target_stride(0.3, 0.1, "x"), 3);  // 2.9999999999999996: within 1e-9
  EXPECT_THROW(pp::target_stride(0.0105, 0.001, "x"), DataError);
  EXPECT_THROW(pp::target_stride(0.0005, 0.001, "x"), DataError);
  EXPECT_THROW(pp::target_stride(0.0, 0.001, "x"), DataError);
  EXPECT_EQ(pp::target_rows(0, 25, 10), (std::vector<int>{0, 10, 20}));
  EXPECT_EQ(pp::target_rows(13, 25, 10), (std::vector<int>{7, 17}));  // indices 20, 30
  EXPECT_EQ(pp::target_rows(20, 1, 10), (std::vector<int>{0}));

  const std::vector<Motion> joints = sinusoid_motions(2);
  Recording r;
  r.duration = 7.3456;  // the last nominal instant is 7.346 s
  const symoro::io::Log log = record(joints, r);
  pp::Options every;  // the settling time at the moving ends kept: the whole grid
  every.trim_settling = false;
  for (double interval : pp::paper_intervals()) {
    const pp::Samples s = pp::preprocess(log, interval, every);
    const double span = 7.346;  // grid span of the single piece
    const int expected = static_cast<int>(std::floor(span / interval + 1e-9)) + 1;
    EXPECT_EQ(s.time.size(), expected) << interval;
    EXPECT_EQ(s.report.kept_samples, expected);
    EXPECT_EQ(s.q.rows(), expected);
    EXPECT_EQ(s.qdd.cols(), 2);
    for (int i = 0; i < s.time.size(); ++i) EXPECT_NEAR(s.time[i] - log.time[0], i * interval, 1e-12);
  }
}

// ---- The pipeline against exact motions --------------------------------------------------------

// Sums of sinusoids (0.2-3 Hz, 0.1-1 rad) recorded as the arm records them: 40 us jitter,
// 20 drops of 1-4 rows, 12-bit q, quantized noisy tau with a 0.3 N m, 100 Hz backlash
// oscillation. Reference: the exact motion with each sinusoid scaled by the filter's |H|^2 (a
// zero-phase filter neither shifts nor otherwise distorts a sinusoid), at Samples.time.
//
// Bounds, at every kept sample at least 6 time constants (analog_time_constant) from a piece
// end ("inside"):
//  - RMS error < 1.3 sigma_m, sigma_m from filtered_noise_sigma (white quantization noise of
//    step / sqrt(12) through |H|^4 and the differences; at 15 Hz 7.3e-5 rad, 3.7e-3 rad/s,
//    0.27 rad/s^2). The white model holds while the joints move more than a step per filter
//    window; the margin covers the turning points.
//  - max error < ||D_m h||_1 (step / 2 + qdd_max g^2 / 8) + truncation: the deterministic
//    bound of impulse_response_l1 with the grid's pointwise error (quantization, plus linear
//    bridging across a gap of g = 5 ms), plus the differences' truncation h^2/6 max|q'''| and
//    h^2/12 max|q''''|. At 15 Hz: 1.4e-3 rad, 0.084 rad/s, 6.4 rad/s^2.
// Within 6 time constants of an end, the odd extension's curvature flip (see zero_phase.hpp)
// dominates; the error must stay under the envelope 2 qdd_max tau^(2-m) e^(-d/tau) plus the
// inside bound, d the distance to the end. Measured values are printed.
TEST(PreprocessPipeline, RecoversSinusoidsAndDerivativesAtEveryKeptSample) {
  const int dof = 4;
  const std::vector<Motion> joints = sinusoid_motions(dof);
  Recording r;
  r.dropped = typical_drops(20001, 7);
  const symoro::io::Log log = record(joints, r);
  // Bridged gaps, for the torque check below: the 100 Hz oscillation cannot be recovered across
  // missing rows and its linear bridge leaves an error of up to 2 * 0.3 N m on each one.
  std::vector<double> gap_times;
  for (int i = 1; i < log.samples(); ++i)
    if (log.time[i] - log.time[i - 1] > 1.5 * kH) gap_times.push_back(log.time[i]);
  for (double interval : pp::paper_intervals()) {
    const pp::Samples s = pp::preprocess(log, interval);
    const double fc = s.report.cutoff;
    EXPECT_DOUBLE_EQ(fc, std::min(15.0, 0.8 * 0.5 / interval));
    EXPECT_EQ(s.report.pieces, 1);
    EXPECT_GE(s.report.gaps_bridged, 15);
    EXPECT_EQ(s.report.missing_samples, static_cast<int>(r.dropped.size()));
    const auto gain = [&](double f) { return bilinear_butterworth_power(f, fc, 4); };
    const double tau = analog_time_constant(fc, 4);
    const double sigma_q = kEncoderStep / std::sqrt(12.0);
    const std::array<double, 3> l1 = impulse_response_l1(fc, 4, tau / kH);
    double qdd_max = 0, q3_max = 0, q4_max = 0;  // of the motion, for the bounds
    for (const Motion& m : joints) {
      double a2 = 0, a3 = 0, a4 = 0;
      for (const Sinusoid& c : m.sinusoids) {
        const double w = 2 * kPi * c.frequency;
        a2 += c.amplitude * w * w;
        a3 += c.amplitude * w * w * w;
        a4 += c.amplitude * w * w * w * w;
      }
      qdd_max = std::max(qdd_max, a2);
      q3_max = std::max(q3_max, a3);
      q4_max = std::max(q4_max, a4);
    }
    const double gap = 0.005, grid_error = kEncoderStep / 2 + qdd_max * gap * gap / 8;
    const double truncation[3] = {0, kH * kH / 6 * q3_max, kH * kH / 12 * q4_max};
    double sigma[3], bound[3];
    for (int m = 0; m < 3; ++m) {
      sigma[m] = filtered_noise_sigma(sigma_q, fc, 4, m);
      bound[m] = l1[m] * grid_error + truncation[m];
    }
    ErrorStats inside[3], edge[3], torque, torque_near_gap;
    double envelope_use = 0;  // largest edge error / its envelope
    const double t_first = s.time[0], t_last = s.time[s.time.size() - 1];
    for (int i = 0; i < s.time.size(); ++i) {
      const double t = s.time[i] - r.start;
      const double d = std::min(s.time[i] - t_first, t_last - s.time[i]);
      const bool near_edge = d < 6 * tau;
      double from_gap = 1e9;
      for (double g : gap_times) from_gap = std::min(from_gap, std::abs(s.time[i] - g));
      for (int j = 0; j < dof; ++j) {
        const Eigen::Vector3d estimate(s.q(i, j), s.qd(i, j), s.qdd(i, j));
        for (int m = 0; m < 3; ++m) {
          const double e = estimate[m] - joints[j].eval(t, m, gain);
          (near_edge ? edge[m] : inside[m]).add(e);
          if (near_edge) {
            const double envelope = 2 * qdd_max * std::pow(tau, 2 - m) * std::exp(-d / tau) + bound[m];
            envelope_use = std::max(envelope_use, std::abs(e) / envelope);
          }
        }
        if (!near_edge)
          (from_gap < 6 * tau ? torque_near_gap : torque).add(s.tau(i, j) - torque_motion(j).eval(t, 0, gain));
      }
    }
    const char* names[3] = {"q", "qd", "qdd"};
    for (int m = 0; m < 3; ++m) {
      EXPECT_LT(inside[m].root_mean_square(), 1.3 * sigma[m]) << names[m] << " at " << interval;
      EXPECT_LT(inside[m].max, bound[m]) << names[m] << " at " << interval;
      std::printf(
          "  %2.0f ms, %5.2f Hz: %-3s inside rms %.2g (%.2f sigma) max %.2g (%.2f of bound "
          "%.2g); within 6 tau of an end max %.2g\n",
          interval * 1e3, fc, names[m], inside[m].root_mean_square(), inside[m].root_mean_square() / sigma[m],
          inside[m].max, inside[m].max / bound[m], bound[m], edge[m].max);
    }
    EXPECT_LT(envelope_use, 1.0) << interval;
    // tau: quantization (0.006 / sqrt(12)) and N(0, 0.01) noise, white, through |H|^4: max of
    // ~5000 samples < 5.5 sigma. Near a bridged gap add the bridge's error through the filter:
    // at most h_max * 4 missing rows * 2 * 0.3 N m, h_max = 2 fc / fs * 1.03 (peak of h).
    const double sigma_tau = filtered_noise_sigma(std::hypot(kCurrentStep / std::sqrt(12.0), 0.01), fc, 4, 0);
    const double bridge = 2 * fc * kH * 1.03 * 4 * 2 * r.backlash;
    EXPECT_LT(torque.max, 5.5 * sigma_tau) << interval;
    EXPECT_LT(torque_near_gap.max, 5.5 * sigma_tau + bridge) << interval;
    std::printf(
        "  %2.0f ms: tau max %.2g N m (%.2f sigma), near gaps %.2g (bound %.2g); "
        "edge envelope used %.2f\n",
        interval * 1e3, torque.max, torque.max / sigma_tau, torque_near_gap.max, 5.5 * sigma_tau + bridge,
        envelope_use);
  }
}

// A cubic passes the zero-phase Butterworth unchanged (|H|^2 = 1 - O(w^2N): the filter's
// moments up to order 2N - 1 = 7 vanish), so the exact polynomial is the reference. Its slow
// stretch (|qd| < 0.04 rad/s for 5-8 s) makes the quantization error a slow staircase, not
// white noise: only the deterministic bound of the test above applies (q''' = 0.024, so no
// truncation term).
TEST(PreprocessPipeline, RecoversAPolynomial) {
  Motion m;
  m.polynomial = {0.2, 0.5, -0.08, 0.004};  // |q| < 1 rad, |qd| < 0.5 rad/s over 20 s
  Recording r;
  r.dropped = typical_drops(20001, 11);
  const symoro::io::Log log = record({m}, r);
  for (double interval : {0.010, 0.080}) {
    const pp::Samples s = pp::preprocess(log, interval);
    const double fc = s.report.cutoff, tau = analog_time_constant(fc, 4);
    const std::array<double, 3> l1 = impulse_response_l1(fc, 4, tau / kH);
    const double grid_error = kEncoderStep / 2 + 0.32 * 0.005 * 0.005 / 8;  // |qdd| <= 0.32
    ErrorStats inside[3];
    for (int i = 0; i < s.time.size(); ++i) {
      if (std::min(s.time[i] - s.time[0], s.time[s.time.size() - 1] - s.time[i]) < 6 * tau) continue;
      const double t = s.time[i] - r.start;
      for (int k = 0; k < 3; ++k)
        inside[k].add((k == 0 ? s.q(i, 0) : k == 1 ? s.qd(i, 0) : s.qdd(i, 0)) - m.eval(t, k));
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT(inside[k].max, l1[k] * grid_error) << k << " at " << interval;
      std::printf(
          "  polynomial, %2.0f ms, derivative %d: rms %.2g max %.2g (bound %.2g, white "
          "sigma %.2g)\n",
          interval * 1e3, k, inside[k].root_mean_square(), inside[k].max, l1[k] * grid_error,
          filtered_noise_sigma(kEncoderStep / std::sqrt(12.0), fc, 4, k));
    }
  }
}

// The brief's pass-band requirement: a 1 Hz sine comes out with < 0.1 % amplitude error at
// every interval (|H|^2(1 Hz) = 1 - 4e-6 even at the 5 Hz cutoff of 80 ms). Without
// quantization, so the amplitude is measured exactly by a fit over the interior.
TEST(PreprocessPipeline, OneHertzPassesWithin0p1Percent) {
  Motion m;
  m.sinusoids = {{0.8, 1.0, 0.4}};
  Recording r;
  r.quantize = false;
  r.duration = 10;
  r.dropped = typical_drops(10001, 3);
  const symoro::io::Log log = record({m}, r);
  for (double interval : pp::paper_intervals()) {
    const pp::Samples s = pp::preprocess(log, interval);
    const int n = static_cast<int>(s.time.size());
    const int skip = n / 10;
    Eigen::MatrixXd basis(n - 2 * skip, 2);
    for (int i = skip; i < n - skip; ++i) {
      const double arg = 2 * kPi * (s.time[i] - r.start) + 0.4;
      basis.row(i - skip) << std::sin(arg), std::cos(arg);
    }
    const Eigen::Vector2d fit = basis.colPivHouseholderQr().solve(s.q.col(0).segment(skip, n - 2 * skip));
    EXPECT_LT(std::abs(std::hypot(fit[0], fit[1]) / 0.8 - 1), 1e-3) << interval;
    EXPECT_LT(std::abs(std::atan2(fit[1], fit[0])), 1e-5) << interval;  // and no delay
  }
}

// q and tau go through the same filter: the same column in both comes out identical.
TEST(PreprocessPipeline, SameFilterOnQAndTau) {
  Recording r;
  r.duration = 3;
  r.dropped = {500, 501, 1700};
  symoro::io::Log log = record(sinusoid_motions(3), r);
  log.tau = log.q;
  const pp::Samples s = pp::preprocess(log, 0.040);
  EXPECT_EQ((s.tau - s.q).cwiseAbs().maxCoeff(), 0.0);
}

// ---- Rejected inputs ---------------------------------------------------------------------------

TEST(PreprocessRejects, BadInputsThrowDataError) {
  Recording r;
  r.duration = 2;
  const symoro::io::Log good = record(sinusoid_motions(2), r);
  EXPECT_THROW(pp::preprocess(good, 0.0105), DataError);  // not a multiple of 1 ms
  EXPECT_THROW(pp::preprocess(good, 0.0), DataError);

  r.duration = 0.05;  // 51 samples: less than the 84-sample padding of a 15 Hz filter
  const symoro::io::Log short_log = record(sinusoid_motions(2), r);
  try {
    pp::preprocess(short_log, 0.010);
    ADD_FAILURE() << "a 50 ms log was accepted";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), "synthetic");
    EXPECT_EQ(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos) << e.what();
  }

  symoro::io::Log repeated = good;
  repeated.time[700] = repeated.time[699];
  EXPECT_THROW(pp::preprocess(repeated, 0.010), DataError);
  symoro::io::Log backwards = good;
  std::swap(backwards.time[10], backwards.time[11]);
  EXPECT_THROW(pp::preprocess(backwards, 0.010), DataError);

  symoro::io::Log not_a_number = good;
  not_a_number.q(300, 1) = std::nan("");
  EXPECT_THROW(pp::preprocess(not_a_number, 0.010), DataError);
  symoro::io::Log mismatched = good;
  mismatched.tau.conservativeResize(Eigen::NoChange, 1);
  EXPECT_THROW(pp::preprocess(mismatched, 0.010), DataError);

  // Stamps every 2 ms against a 1 ms base period: a different log, not jitter to correct.
  symoro::io::Log slow = good;
  slow.time *= 2;
  EXPECT_THROW(pp::preprocess(slow, 0.010), DataError);
  symoro::io::Log unnamed = slow;
  unnamed.meta.trajectory.clear();
  try {
    pp::preprocess(unnamed, 0.010);
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), "log");
  }
}

TEST(PreprocessReport, SummaryIsOneLine) {
  Recording r;
  r.duration = 2;
  r.dropped = {400, 401};
  const pp::Samples s = pp::preprocess(record(sinusoid_motions(1), r), 0.020);
  const std::string line = s.report.summary();
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_NE(line.find("1999 raw samples"), std::string::npos) << line;
  EXPECT_NE(line.find("1 gaps bridged (2 samples filled in)"), std::string::npos) << line;
  // 2 s of a motion moving at both ends: the samples within 6 time constants of 15 Hz (0.167 s) of
  // either end, 9 at each, are left out of the 101 on the 20 ms grid.
  EXPECT_NE(
      line.find("18 samples within the filter's settling time (0.167 s) of 2 moving ends left out, 83 samples kept"),
      std::string::npos)
      << line;
  std::printf("  %s\n", line.c_str());
}

// ---- Stale rows, the base period from the log, the logged velocity ------------------------------

namespace {

// A log of n rows and `joints` joints on the 1 ms period, its values to be filled in.
symoro::io::Log sized_log(const char* name, int n, int joints) {
  symoro::io::Log log;
  log.meta.trajectory = name;
  log.meta.sample_time = kH;
  log.time.resize(n);
  log.q.resize(n, joints);
  log.qd.resize(n, joints);
  log.tau.resize(n, joints);
  return log;
}

// q = 0.8 sin(pi t) rad on exact 1 ms stamps from t = 0, qd its derivative, a smooth tau.
symoro::io::Log clean_sine_log(double seconds) {
  const int n = static_cast<int>(std::lround(seconds / kH)) + 1;
  symoro::io::Log log = sized_log("sine", n, 1);
  for (int k = 0; k < n; ++k) {
    const double t = k * kH;
    log.time[k] = t;
    log.q(k, 0) = 0.8 * std::sin(kPi * t);
    log.qd(k, 0) = 0.8 * kPi * std::cos(kPi * t);
    log.tau(k, 0) = 1 + 0.3 * std::sin(2 * kPi * 0.7 * t);
  }
  return log;
}

}  // namespace

// A logger hiccup: rows 2001-2005 repeat row 2000 (t = 2 s, where qd = 0.8 pi = 2.51 rad/s and
// qdd = 0). Kept, they hold q back by qd * i h at the i-th: a raw error of area
// h * sum_i (q(2) - q(2 + i h)) = -qd h^2 (1 + ... + 5) = -3.77e-5 rad s to first order (the sum
// itself is the reference). The zero-phase filter has unit DC gain, so the filtered q error keeps
// that area, spread into a velocity dip. Left out, the 6 ms hole is bridged linearly between
// t = 2 and 2.006 s, where qdd = 0: the bridge errs by about q3 g^3 / 16 ~ 3e-7 rad at most.
TEST(PreprocessStale, LeavingOutStaleRowsRemovesTheVelocityDip) {
  symoro::io::Log log = clean_sine_log(6.0);
  const int burst = 2000;
  for (int i = 1; i <= 5; ++i) {
    log.q.row(burst + i) = log.q.row(burst);
    log.qd.row(burst + i) = log.qd.row(burst);
    log.tau.row(burst + i) = log.tau.row(burst);
  }
  double expected_area = 0;
  for (int i = 1; i <= 5; ++i) expected_area += kH * (0.8 * std::sin(kPi * 2.0) - 0.8 * std::sin(kPi * (2.0 + i * kH)));
  EXPECT_NEAR(expected_area, -0.8 * kPi * kH * kH * 15, 1e-9);

  struct Outcome {
    double area = 0, qd_max = 0;
    pp::Report report;
  };
  const auto run = [&](bool drop) {
    pp::Options o;
    o.drop_stale = drop;
    const pp::Samples s = pp::preprocess(log, kH, o);
    Outcome out;
    out.report = s.report;
    for (int i = 0; i < s.time.size(); ++i) {
      const double t = s.time[i];
      if (t < 0.5 || t > 5.5) continue;  // 18 filter time constants from either end
      if (std::abs(t - 2.0025) < 0.3) out.area += kH * (s.q(i, 0) - 0.8 * std::sin(kPi * t));
      out.qd_max = std::max(out.qd_max, std::abs(s.qd(i, 0) - 0.8 * kPi * std::cos(kPi * t)));
    }
    return out;
  };
  const Outcome kept = run(false), dropped = run(true);
  EXPECT_EQ(kept.report.stale_rows, 0);
  EXPECT_EQ(dropped.report.stale_rows, 5);
  EXPECT_EQ(dropped.report.missing_samples, 5);
  EXPECT_EQ(dropped.report.gaps_bridged, 1);
  EXPECT_EQ(dropped.report.raw_samples, 6001);
  EXPECT_NE(dropped.report.summary().find("5 stale rows left out"), std::string::npos) << dropped.report.summary();
  // Kept: the hand-derived area, to 1 % (the tails beyond 0.3 s are e^-10 of it).
  EXPECT_NEAR(kept.area / expected_area, 1.0, 0.01);
  EXPECT_GT(kept.qd_max, 0.02);
  // Left out: no area and no dip (the filtered sine's own error is ~1e-12).
  EXPECT_LT(std::abs(dropped.area), 1e-3 * std::abs(expected_area));
  EXPECT_LT(dropped.qd_max, 1e-3);
  std::printf("  stale burst: area %.3g (hand %.3g) -> %.2g; qd max error %.3g -> %.2g rad/s\n", kept.area,
              expected_area, dropped.area, kept.qd_max, dropped.qd_max);
}

// An arm at rest repeats q, tau and a zero qd: not a stale read, nothing is left out.
TEST(PreprocessStale, RestIsNotStale) {
  symoro::io::Log log = clean_sine_log(2.0);
  log.q.setConstant(0.25);
  log.qd.setZero();
  log.tau.setConstant(1.5);
  const pp::Samples s = pp::preprocess(log, 0.010);
  EXPECT_EQ(s.report.stale_rows, 0);
  EXPECT_EQ(s.report.pieces, 1);
  EXPECT_EQ(s.report.kept_samples, 201);
  EXPECT_LT((s.q.array() - 0.25).abs().maxCoeff(), 1e-12);
}

// A 500 Hz log: the grid is its sample_time (2 ms), and 10 ms keeps every 5th grid sample. The
// same log without a sample_time gets the same period from its stamps (every 4th is off by
// 30 us, so half the intervals are 2 ms: the median rounds to 2 ms). q = 0.5 sin(2 pi 0.4 t):
// linear interpolation of the jitter errs by at most qdd h^2 / 8 = 8e-7 rad.
TEST(PreprocessBasePeriod, FromTheLogsSampleTime) {
  const double h = 0.002, w = 2 * kPi * 0.4;
  const int n = 5001;  // 10 s
  symoro::io::Log log;
  log.meta.trajectory = "slow";
  log.meta.sample_time = h;
  log.time.resize(n);
  log.q.resize(n, 1);
  log.qd.resize(n, 1);
  log.tau.resize(n, 1);
  for (int k = 0; k < n; ++k) {
    const double t = k * h + (k % 4 == 2 ? 30e-6 : 0.0);
    log.time[k] = t;
    log.q(k, 0) = 0.5 * std::sin(w * t);
    log.qd(k, 0) = 0.5 * w * std::cos(w * t);
    log.tau(k, 0) = std::cos(w * t);
  }
  pp::Options every;  // the settling time at the moving ends kept: the whole grid
  every.trim_settling = false;
  const pp::Samples s = pp::preprocess(log, 0.010, every);
  EXPECT_EQ(s.report.base_period, 0.002);
  ASSERT_EQ(s.time.size(), 1001);  // 0, 10, ..., 10000 ms
  double q_error = 0, qd_error = 0;
  for (int i = 0; i < s.time.size(); ++i) {
    EXPECT_NEAR(s.time[i], i * 0.010, 1e-12);
    if (s.time[i] < 0.5 || s.time[i] > 9.5) continue;
    q_error = std::max(q_error, std::abs(s.q(i, 0) - 0.5 * std::sin(w * s.time[i])));
    qd_error = std::max(qd_error, std::abs(s.qd(i, 0) - 0.5 * w * std::cos(w * s.time[i])));
  }
  EXPECT_LT(q_error, 1e-5);
  EXPECT_LT(qd_error, 1e-3);

  symoro::io::Log unstated = log;
  unstated.meta.sample_time = 0;
  const pp::Samples u = pp::preprocess(unstated, 0.010, every);
  EXPECT_EQ(u.report.base_period, 0.002);
  EXPECT_EQ(u.q, s.q);

  pp::Options forced;
  forced.base_period = 0.001;  // a flag may force a period; here it contradicts the stamps
  EXPECT_THROW(pp::preprocess(log, 0.010, forced), DataError);
  try {
    pp::preprocess(log, 0.011);
    ADD_FAILURE() << "11 ms accepted on a 2 ms grid";
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("base period 0.002 s (the log's sample_time); nearest valid intervals: 0.01 s and 0.012 s"),
              std::string::npos)
        << what;
  }
}

// qd from the log (exact here) instead of differences of a 12-bit q: the filtered logged
// velocity errs by the jitter's interpolation, qd'' h^2 / 8 = 3e-6 rad/s, times the filter's
// ||h||_1 = 1.38; differentiating the quantized q leaves ~4e-3 rad/s of noise instead.
TEST(PreprocessLoggedVelocity, FollowsTheAnalyticVelocity) {
  Motion m;
  m.sinusoids = {{0.8, 0.5, 0.3}};
  Recording r;
  r.duration = 8;
  const symoro::io::Log log = record({m}, r);
  pp::Options logged;
  logged.use_logged_velocity = true;
  const pp::Samples a = pp::preprocess(log, 0.010, logged), b = pp::preprocess(log, 0.010);
  double qd_logged = 0, qdd_logged = 0, qd_differenced = 0;
  for (int i = 0; i < a.time.size(); ++i) {
    const double t = a.time[i] - r.start;
    if (t < 0.5 || t > r.duration - 0.5) continue;
    qd_logged = std::max(qd_logged, std::abs(a.qd(i, 0) - m.eval(t, 1)));
    qdd_logged = std::max(qdd_logged, std::abs(a.qdd(i, 0) - m.eval(t, 2)));
    qd_differenced = std::max(qd_differenced, std::abs(b.qd(i, 0) - m.eval(t, 1)));
  }
  EXPECT_LT(qd_logged, 1e-5);
  EXPECT_LT(qdd_logged, 1e-3);
  EXPECT_GT(qd_differenced, 10 * qd_logged);
  EXPECT_EQ(a.q, b.q);  // q is unaffected
  std::printf("  logged velocity: qd max error %.2g, qdd %.2g; from q: qd %.2g rad/s\n", qd_logged, qdd_logged,
              qd_differenced);

  symoro::io::Log differentiated = log;
  differentiated.meta.velocity = symoro::io::Velocity::differentiated;
  EXPECT_THROW(pp::preprocess(differentiated, 0.010, logged), DataError);
}

// ---- Speed (run with --gtest_also_run_disabled_tests; no timed assertion) -----------------------

TEST(PreprocessSpeed, DISABLED_EightJointsHundredTenSeconds) {
  Recording r;
  r.duration = 110;
  r.dropped = typical_drops(110001, 5);
  std::vector<Motion> joints = sinusoid_motions(8);
  const symoro::io::Log log = record(joints, r);
  for (double interval : pp::paper_intervals()) {
    double best = 1e9;
    for (int repeat = 0; repeat < 5; ++repeat) {
      const auto start = std::chrono::steady_clock::now();
      const pp::Samples s = pp::preprocess(log, interval);
      const auto stop = std::chrono::steady_clock::now();
      best = std::min(best, std::chrono::duration<double, std::milli>(stop - start).count());
      ASSERT_GT(s.report.kept_samples, 0);
    }
    std::printf("  %d samples x 8 joints, %2.0f ms interval: %.1f ms (best of 5)\n", log.samples(), interval * 1e3,
                best);
  }
}

// ---- The filter's settling time at the log's own ends (issue 41) ---------------------------------

// A log cut in mid-motion (sinusoids of 0.2-3 Hz, no quantization so that only the filter's ends
// remain): preprocess() returns no sample within 6 slowest time constants of either end, and every
// sample it returns is the motion (through the filter's gain) to 2e-3 of the largest acceleration
// (measured: 1.1e-3 at 10 ms, 4.7e-4 at 40 ms);
// with the trimming off, the samples it then keeps at the ends err by 30 % or more of it (the odd
// reflection's curvature flip: the same log, so the check can fail).
TEST(PreprocessEdges, MovingEndsLoseTheSettlingTimeAndWhatRemainsIsTheMotion) {
  const int dof = 3;
  const std::vector<Motion> joints = sinusoid_motions(dof);
  Recording r;
  r.duration = 8;
  r.quantize = false;
  r.jitter = 0;
  r.backlash = 0;
  const symoro::io::Log log = record(joints, r);
  for (double interval : {0.010, 0.040}) {
    const pp::Samples s = pp::preprocess(log, interval);
    const double fc = s.report.cutoff, tau = analog_time_constant(fc, 4);
    const auto gain = [&](double f) { return bilinear_butterworth_power(f, fc, 4); };
    double qdd_max = 0;
    for (const Motion& m : joints) {
      double a = 0;
      for (const Sinusoid& c : m.sinusoids) a += c.amplitude * std::pow(2 * kPi * c.frequency, 2);
      qdd_max = std::max(qdd_max, a);
    }
    // The settling time: 6 time constants of the analog prototype (the digital one differs by the
    // bilinear warp, < 1 % here), on the base grid.
    EXPECT_NEAR(s.report.settling_seconds, 6 * tau, 0.01 * 6 * tau + kH) << interval;
    const double first = r.start, last = r.start + r.duration;
    int expected_edge = 0;  // target instants within the settling time of an end
    for (long k = 0; k * interval <= r.duration + 1e-9; ++k) {
      const double t = first + k * interval;
      if (t - first < s.report.settling_seconds - 1e-9 || last - t < s.report.settling_seconds - 1e-9) ++expected_edge;
    }
    EXPECT_EQ(s.report.moving_ends, 2) << interval;
    EXPECT_NEAR(s.report.edge_samples, expected_edge, 2) << interval;
    EXPECT_NE(s.report.summary().find("moving ends left out"), std::string::npos) << s.report.summary();
    double worst = 0;
    for (int i = 0; i < s.time.size(); ++i) {
      EXPECT_GE(std::min(s.time[i] - first, last - s.time[i]), s.report.settling_seconds - kH) << interval;
      for (int j = 0; j < dof; ++j)
        worst = std::max(worst, std::abs(s.qdd(i, j) - joints[j].eval(s.time[i] - first, 2, gain)));
    }
    EXPECT_LT(worst, 2e-3 * qdd_max) << interval;

    pp::Options keep;
    keep.trim_settling = false;
    const pp::Samples all = pp::preprocess(log, interval, keep);
    EXPECT_EQ(all.report.edge_samples, 0);
    EXPECT_EQ(all.time.size(), s.time.size() + s.report.edge_samples);
    double at_ends = 0;
    for (int i = 0; i < all.time.size(); ++i)
      for (int j = 0; j < dof; ++j)
        at_ends = std::max(at_ends, std::abs(all.qdd(i, j) - joints[j].eval(all.time[i] - first, 2, gain)));
    EXPECT_GT(at_ends, 0.3 * qdd_max) << interval;
    std::printf(
        "  %2.0f ms: %d samples in the settling time (%.3f s) left out; qdd error %.2g of its largest "
        "(%.2g with them)\n",
        interval * 1e3, s.report.edge_samples, s.report.settling_seconds, worst / qdd_max, at_ends / qdd_max);
  }
}

// A log that starts and ends at rest (q = a (1 - cos(w t))^2: qd = qdd = 0 at both ends, one
// encoder count of quantization toggling there) loses nothing, and a log at rest at one end only
// loses the other end's settling time.
TEST(PreprocessEdges, EndsAtRestKeepEverySample) {
  const double seconds = 10, w = 2 * kPi / seconds;
  const int n = static_cast<int>(seconds / kH) + 1;
  symoro::io::Log log = sized_log("rest to rest", n, 2);
  for (int k = 0; k < n; ++k) {
    const double t = k * kH;
    log.time[k] = t;
    for (int j = 0; j < 2; ++j) {
      const double a = 0.4 + 0.3 * j, c = 1 - std::cos(w * t);
      // Half a count of offset and a 37 Hz vibration of 0.3 count: one count toggling at rest.
      log.q(k, j) = kEncoderStep *
                    std::round((a * c * c + (0.5 + 0.3 * std::sin(2 * kPi * 37 * t)) * kEncoderStep) / kEncoderStep);
      log.qd(k, j) = 2 * a * c * w * std::sin(w * t);
      log.tau(k, j) = log.q(k, j);
    }
  }
  for (double interval : {0.001, 0.010}) {
    const pp::Samples s = pp::preprocess(log, interval);
    EXPECT_EQ(s.report.moving_ends, 0) << interval;
    EXPECT_EQ(s.report.edge_samples, 0) << interval;
    EXPECT_EQ(s.report.kept_samples, static_cast<int>(std::lround(seconds / interval)) + 1) << interval;
  }
  // Cut at 60 % of the motion: at rest at the start, moving at the end.
  const int cut = n * 6 / 10;
  symoro::io::Log head = log;
  head.time = log.time.head(cut);
  for (auto* m : {&head.q, &head.qd, &head.tau}) *m = Eigen::MatrixXd(m->topRows(cut));
  const pp::Samples s = pp::preprocess(head, 0.010);
  EXPECT_EQ(s.report.moving_ends, 1);
  EXPECT_GT(s.report.edge_samples, 0);
  EXPECT_NEAR(s.time[s.time.size() - 1], head.time[cut - 1] - s.report.settling_seconds, 0.011);
  EXPECT_EQ(s.time[0], 0.0);
}

// A joint held still without a sensor's steps (a logged reference, a simulated hold) is still:
// interpolating it onto the grid between jittered stamps leaves differences of a rounding, and
// its ends were taken to move (a reference's first samples left out, the measured log's kept).
TEST(PreprocessEdges, AJointHeldExactlyStillIsNotMoving) {
  const double seconds = 4, w = 2 * kPi / seconds;
  const int n = static_cast<int>(seconds / kH) + 1;
  symoro::io::Log log = sized_log("held", n, 2);
  for (int k = 0; k < n; ++k) {
    const double t = k * kH, c = 1 - std::cos(w * t);
    log.time[k] = t + (k % 7 == 3 ? 1e-4 : 0.0) - (k % 11 == 5 ? 7e-5 : 0.0);
    log.q(k, 0) = 0.7309217653;
    log.q(k, 1) = -1.3 + 0.5 * c * c;
    log.qd(k, 0) = 0;
    log.qd(k, 1) = w * c * std::sin(w * t);
    log.tau(k, 0) = 0.1 * std::sin(3 * t);
    log.tau(k, 1) = log.q(k, 1);
  }
  const pp::Samples s = pp::preprocess(log, 0.010);
  EXPECT_EQ(s.report.moving_ends, 0);
  EXPECT_EQ(s.report.edge_samples, 0);
  EXPECT_EQ(s.time[0], 0.0);
}

// A run's window of a longer file (a split's held-out part, io::read_run_log) is filtered as the
// whole file: its samples are the uncut file's at the same instants, to rounding, whatever clock
// the caller counts it on; a window whose rows no longer match its file is filtered alone.
TEST(PreprocessEdges, AWindowIsTheUncutFilesSamples) {
  Recording r;
  r.duration = 6;
  r.dropped = typical_drops(6001, 3);
  const symoro::io::Log log = record(sinusoid_motions(2), r);
  const auto dir = std::filesystem::temp_directory_path() / ("symoro_window_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  symoro::io::Log written = log;
  written.meta.robot = "synthetic";
  written.meta.source = "robot";
  written.meta.joints = {"a", "b"};
  symoro::io::write_log(dir / "run.csv", written);
  const double split = r.start + 4.2;  // in mid-motion
  symoro::io::DatasetRun fit{"run", "E", 1, dir / "run.csv", -INFINITY, split};
  symoro::io::DatasetRun held{"run_heldout", "V", 1, dir / "run.csv", split, INFINITY};
  const pp::Samples whole = pp::preprocess(symoro::io::read_log(dir / "run.csv"), 0.010);
  for (const auto* run : {&fit, &held}) {
    symoro::io::Log part = symoro::io::read_run_log(*run);
    const pp::Samples s = pp::preprocess(part, 0.010);
    EXPECT_EQ(s.report.context_rows, log.samples() - part.samples()) << run->trajectory;
    EXPECT_EQ(s.report.raw_samples, part.samples());
    EXPECT_EQ(s.report.moving_ends, 1) << run->trajectory << ": only the file's own end is an edge";
    ASSERT_GT(s.time.size(), 100);
    // The uncut file's samples at the same instants: its times count from the file's first stamp,
    // the window's from its own first stamp (a closed loop's cycle 0), each in whole base periods;
    // they differ by the two first stamps' jitter.
    for (Eigen::Index i = 0; i < s.time.size(); ++i) {
      const double cycles = (s.time[i] - part.time(0)) / kH;
      EXPECT_NEAR(cycles, std::round(cycles), 1e-6);
    }
    Eigen::Index at = 0;
    while (at < whole.time.size() && whole.time[at] < s.time[0] - 0.5 * kH) ++at;
    ASSERT_LE(at + s.time.size(), whole.time.size());
    EXPECT_NEAR(whole.time[at], s.time[0], 2 * r.jitter + 1e-12);  // both first stamps jitter
    for (auto [a, b] : {std::pair{&s.q, &whole.q}, std::pair{&s.qdd, &whole.qdd}, std::pair{&s.tau, &whole.tau}})
      EXPECT_LT((*a - b->middleRows(at, s.time.size())).cwiseAbs().maxCoeff(), 1e-12 * (1 + b->cwiseAbs().maxCoeff()));
    // The same window on a clock that starts at its first row (the study's).
    const double t0 = part.time(0);
    part.time.array() -= t0;
    const pp::Samples shifted = pp::preprocess(part, 0.010);
    ASSERT_EQ(shifted.time.size(), s.time.size());
    EXPECT_LT((shifted.qdd - s.qdd).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_NEAR(shifted.time[0] + t0, s.time[0], 1e-9);
    // Edited after the cut: no longer the file's rows, filtered alone.
    part.q(0, 0) += 0.01;
    EXPECT_EQ(pp::preprocess(part, 0.010).report.context_rows, 0);
  }
  std::filesystem::remove_all(dir);
}
