// The localization stage against independent references: Welch's PSD of a sinusoid in white
// noise (peak, A^2/2, the 2 sigma^2 dt floor) and Parseval over pieces; band fractions of
// bin-centred sinusoids; the torque lag of a band-limited signal shifted by a known (fractional)
// delay; the residual-velocity lag; N_eff of AR(1) against (1 - a)/(1 + a) N; a Coulomb residual
// (direction step, its standard error against the white-noise formula and against Monte Carlo
// with AR(1) noise, the square wave's correlation with qd and its power below 0.5 Hz); regime
// statistics against masks computed directly from analytic motion; the Markdown's rows; the
// figures parsed as XML with one panel per joint and decimated scatter.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "symoro/diagnose/localize.hpp"
#include "symoro/diagnose/localize_report.hpp"
#include "svg_test_support.hpp"

namespace {

using namespace symoro::diagnose;
namespace fs = std::filesystem;
constexpr double pi = 3.14159265358979323846;

// --- Helpers ------------------------------------------------------------------------------

// Trapezoid-free integral of a one-sided PSD: sum of bins times the bin width (Welch's bins are
// a Riemann sum of the density; Parseval holds for this sum exactly per segment).
double integral(const Psd& psd, int column, double f_lo = -1, double f_hi = 1e300) {
  const double df = psd.frequency(1) - psd.frequency(0);
  double sum = 0;
  for (Eigen::Index k = 0; k < psd.frequency.size(); ++k)
    if (psd.frequency(k) >= f_lo && psd.frequency(k) <= f_hi) sum += psd.power(k, column);
  return sum * df;
}

// A band-limited random signal: a sum of sinusoids with random frequencies in [f_lo, f_hi],
// amplitudes and phases; evaluable at any time, so shifted copies are exact.
struct BandLimited {
  std::vector<double> a, f, phase;
  BandLimited(unsigned seed, int count, double f_lo, double f_hi) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < count; ++i) {
      a.push_back(0.2 + u(rng));
      f.push_back(f_lo + (f_hi - f_lo) * u(rng));
      phase.push_back(2 * pi * u(rng));
    }
  }
  double operator()(double t) const {
    double s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * std::sin(2 * pi * f[i] * t + phase[i]);
    return s;
  }
};

// AR(1): x_k = a x_{k-1} + e_k, e ~ N(0, (1 - a^2) sigma^2), so that Var x = sigma^2.
Eigen::VectorXd ar1(std::mt19937& rng, Eigen::Index n, double a, double sigma) {
  std::normal_distribution<double> e(0, sigma * std::sqrt(1 - a * a));
  Eigen::VectorXd x(n);
  double prev = std::normal_distribution<double>(0, sigma)(rng);
  for (Eigen::Index i = 0; i < n; ++i) prev = x(i) = a * prev + e(rng);
  return x;
}

// A one-joint-per-column series of sinusoidal motions q_j = A_j sin(w_j t + phi_j) (analytic qd
// and qdd), the residual given per sample, and a smooth model torque.
struct Motion {
  double amplitude, omega, phase;
  double q(double t) const { return amplitude * std::sin(omega * t + phase); }
  double qd(double t) const { return amplitude * omega * std::cos(omega * t + phase); }
  double qdd(double t) const { return -amplitude * omega * omega * std::sin(omega * t + phase); }
};

template <class Residual>
ResidualSeries make_series(const std::string& name, double t0, int n, double dt, const std::vector<Motion>& motion,
                           Residual residual) {
  ResidualSeries s;
  s.name = name;
  s.interval = dt;
  const auto joints = static_cast<Eigen::Index>(motion.size());
  s.time.resize(n);
  for (auto* m : {&s.q, &s.qd, &s.qdd, &s.tau_measured, &s.tau_model}) m->resize(n, joints);
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i * dt;
    s.time(i) = t;
    for (Eigen::Index j = 0; j < joints; ++j) {
      const Motion& m = motion[static_cast<std::size_t>(j)];
      s.q(i, j) = m.q(t), s.qd(i, j) = m.qd(t), s.qdd(i, j) = m.qdd(t);
      s.tau_model(i, j) = 2 * std::sin(m.q(t)) + 0.3 * m.qdd(t) + 0.1 * static_cast<double>(j);
      s.tau_measured(i, j) = s.tau_model(i, j) + residual(i, j, t);
    }
  }
  return s;
}

const RegimeStat& regime(const JointLocalization& jl, const std::string& starts) {
  for (const auto& r : jl.regimes)
    if (r.regime.rfind(starts, 0) == 0) return r;
  ADD_FAILURE() << "no regime starting with " << starts;
  static RegimeStat none;
  return none;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
  return n;
}

// A strict little XML well-formedness parser (no DTD): one root element, names, quoted
// attributes without '<', valid entity and character references, balanced tags, comments,
// processing instructions. Returns an empty string when well-formed, else what went wrong.
class XmlCheck {
 public:
  explicit XmlCheck(const std::string& s) : s_(s) {}
  std::string run() {
    try {
      skip_misc();
      if (!element()) return "no root element";
      skip_misc();
      if (i_ != s_.size()) return "content after the root element at " + std::to_string(i_);
      return "";
    } catch (const std::string& e) {
      return e + " at " + std::to_string(i_);
    }
  }
  int elements = 0;

 private:
  const std::string& s_;
  std::size_t i_ = 0;
  bool at(const char* p) const { return s_.compare(i_, std::strlen(p), p) == 0; }
  void ws() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  void skip_until(const char* end) {
    const auto pos = s_.find(end, i_);
    if (pos == std::string::npos) throw std::string("unterminated ") + end;
    i_ = pos + std::strlen(end);
  }
  void skip_misc() {
    for (;;) {
      ws();
      if (at("<?"))
        skip_until("?>");
      else if (at("<!--"))
        skip_until("-->");
      else
        return;
    }
  }
  std::string name() {
    const std::size_t b = i_;
    auto first = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == ':'; };
    if (i_ >= s_.size() || !first(s_[i_])) throw std::string("bad name");
    while (i_ < s_.size() &&
           (first(s_[i_]) || std::isdigit(static_cast<unsigned char>(s_[i_])) || s_[i_] == '-' || s_[i_] == '.'))
      ++i_;
    return s_.substr(b, i_ - b);
  }
  void reference() {  // at '&'
    const auto end = s_.find(';', i_);
    if (end == std::string::npos || end - i_ > 10) throw std::string("bad reference");
    const std::string r = s_.substr(i_ + 1, end - i_ - 1);
    const bool named = r == "amp" || r == "lt" || r == "gt" || r == "quot" || r == "apos";
    const bool numeric =
        r.size() > 1 && r[0] == '#' && std::all_of(r.begin() + (r[1] == 'x' ? 2 : 1), r.end(), [&](char c) {
          return r[1] == 'x' ? std::isxdigit(static_cast<unsigned char>(c)) != 0
                             : std::isdigit(static_cast<unsigned char>(c)) != 0;
        });
    if (!named && !numeric) throw std::string("unknown reference &") + r + ";";
    i_ = end + 1;
  }
  bool element() {
    if (!at("<") || at("</")) return false;
    ++i_;
    const std::string tag = name();
    ++elements;
    std::vector<std::string> attributes;
    for (;;) {
      const std::size_t before = i_;
      ws();
      if (at("/>")) {
        i_ += 2;
        return true;
      }
      if (at(">")) {
        ++i_;
        break;
      }
      if (i_ == before) throw std::string("attributes need white space");
      const std::string a = name();
      if (std::find(attributes.begin(), attributes.end(), a) != attributes.end())
        throw std::string("duplicate attribute ") + a;
      attributes.push_back(a);
      ws();
      if (!at("=")) throw std::string("attribute without =");
      ++i_;
      ws();
      if (i_ >= s_.size() || (s_[i_] != '"' && s_[i_] != '\'')) throw std::string("unquoted attribute");
      const char quote = s_[i_++];
      while (i_ < s_.size() && s_[i_] != quote) {
        if (s_[i_] == '<') throw std::string("'<' in an attribute");
        if (s_[i_] == '&')
          reference();
        else
          ++i_;
      }
      if (i_ >= s_.size()) throw std::string("unterminated attribute");
      ++i_;
    }
    for (;;) {  // content
      if (i_ >= s_.size()) throw std::string("unclosed <") + tag + ">";
      if (at("</")) {
        i_ += 2;
        if (name() != tag) throw std::string("mismatched </...> for <") + tag + ">";
        ws();
        if (!at(">")) throw std::string("bad end tag");
        ++i_;
        return true;
      }
      if (at("<!--"))
        skip_until("-->");
      else if (at("<?"))
        skip_until("?>");
      else if (at("<"))
        element();
      else if (s_[i_] == '&')
        reference();
      else
        ++i_;
    }
  }
};

using symoro::test::panels;

// --- Welch ----------------------------------------------------------------------------------

TEST(DiagnoseWelch, SegmentLengthIsThePowerOfTwoOfTheRequestedDuration) {
  EXPECT_EQ(welch_segment_length(0.001, 2.0), 2048);
  EXPECT_EQ(welch_segment_length(0.01, 2.0), 256);
  EXPECT_EQ(welch_segment_length(0.08, 2.0), 32);
  EXPECT_EQ(welch_segment_length(0.01, 2.56), 256);  // exactly 2.56 s: no doubling
}

TEST(DiagnoseWelch, SinusoidInWhiteNoisePeakPowerAndFloor) {
  const double dt = 0.001, amplitude = 0.3, f0 = 12.3, sigma = 0.05;
  const Eigen::Index n = 300000;  // 300 s: ~290 segments
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, sigma);
  Eigen::MatrixXd x(n, 1);
  for (Eigen::Index i = 0; i < n; ++i) x(i, 0) = amplitude * std::sin(2 * pi * f0 * i * dt + 0.4) + noise(rng);
  const int length = welch_segment_length(dt, 2.0);
  const Psd psd = welch({x}, dt, length);
  ASSERT_EQ(psd.segment_length, 2048);
  EXPECT_EQ(psd.segments, static_cast<int>((n - 2048) / 1024 + 1));
  ASSERT_EQ(psd.frequency.size(), 1025);
  const double df = 1 / (2048 * dt);
  EXPECT_NEAR(psd.frequency(1), df, 1e-12);
  EXPECT_NEAR(psd.frequency(1024), 500, 1e-9);

  Eigen::Index peak = 0;
  psd.power.col(0).maxCoeff(&peak);
  EXPECT_NEAR(psd.frequency(peak), f0, df);

  // The floor, far from the peak: one-sided white noise density 2 sigma^2 dt.
  const double floor_expected = 2 * sigma * sigma * dt;
  double floor_sum = 0;
  int floor_bins = 0;
  for (Eigen::Index k = 0; k < psd.frequency.size(); ++k)
    if (psd.frequency(k) > 50 && psd.frequency(k) < 450) floor_sum += psd.power(k, 0), ++floor_bins;
  const double floor = floor_sum / floor_bins;
  EXPECT_NEAR(floor / floor_expected, 1, 0.03) << floor << " vs " << floor_expected;

  // The sinusoid's power A^2 / 2: the integral over +-2 Hz (the Hann main lobe is +-2 bins
  // = +-1 Hz) less the floor under it.
  int window_bins = 0;
  for (Eigen::Index k = 0; k < psd.frequency.size(); ++k)
    if (std::abs(psd.frequency(k) - f0) <= 2) ++window_bins;
  const double sine_power = integral(psd, 0, f0 - 2, f0 + 2) - floor * window_bins * df;
  EXPECT_NEAR(sine_power / (amplitude * amplitude / 2), 1, 0.02) << sine_power;
}

TEST(DiagnoseWelch, ParsevalOverPiecesOfUnequalLength) {
  // A coloured zero-mean signal (AR(1) plus two tones) in pieces of random length, some shorter
  // than a segment; then with a mean added (not detrended: the mean is power at 0 Hz).
  const double dt = 0.002;
  const int length = welch_segment_length(dt, 2.0);  // 1024
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> piece_length(300, 9000);
  std::vector<Eigen::MatrixXd> pieces;
  double sq0 = 0, sq1 = 0, mean_sq = 0;
  Eigen::Index used = 0;
  const double offset = 0.7;
  for (int p = 0; p < 40; ++p) {
    const int n = piece_length(rng);
    const Eigen::VectorXd noise = ar1(rng, n, 0.95, 0.4);
    Eigen::MatrixXd x(n, 2);
    for (int i = 0; i < n; ++i) {
      const double t = i * dt;
      x(i, 0) = noise(i) + 0.5 * std::sin(2 * pi * 3.3 * t) + 0.2 * std::cos(2 * pi * 41 * t);
      x(i, 1) = x(i, 0) + offset;
    }
    if (n >= length) {
      sq0 += x.col(0).squaredNorm();
      sq1 += x.col(1).squaredNorm();
      mean_sq += x.col(0).sum();
      used += n;
    }
    pieces.push_back(x);
  }
  const Psd psd = welch(pieces, dt, length);
  ASSERT_GT(psd.segments, 100);
  const double variance = sq0 / used - std::pow(mean_sq / used, 2);
  EXPECT_NEAR(integral(psd, 0) / variance, 1, 0.03);
  EXPECT_NEAR(integral(psd, 1) / (sq1 / used), 1, 0.03);
  // The mean's power sits in the lowest bins (DC and the Hann lobe's first neighbour).
  EXPECT_NEAR(
      (integral(psd, 1, -1, 1.5 / (length * dt)) - integral(psd, 0, -1, 1.5 / (length * dt))) / (offset * offset), 1,
      0.05);
}

TEST(DiagnoseWelch, NoSegmentGivesAnEmptySpectrumAndBadLengthsThrow) {
  const Psd psd = welch({Eigen::MatrixXd::Ones(100, 2)}, 0.01, 128);
  EXPECT_EQ(psd.segments, 0);
  EXPECT_EQ(psd.power.rows(), 0);
  EXPECT_THROW(welch({Eigen::MatrixXd::Ones(100, 2)}, 0.01, 127), std::invalid_argument);
  EXPECT_THROW(welch({Eigen::MatrixXd::Ones(100, 2)}, 0.0, 128), std::invalid_argument);
}

// --- Lags -----------------------------------------------------------------------------------

TEST(DiagnoseLag, TorqueLagRecoversKnownShifts) {
  const BandLimited signal(3, 30, 0.2, 6.0);
  struct Case {
    double dt, delay;
  };
  for (const Case c :
       {Case{0.001, 0.0030}, Case{0.001, 0.0024}, Case{0.001, -0.0017}, Case{0.01, 0.0043}, Case{0.01, -0.0312}}) {
    std::mt19937 rng(17);
    std::normal_distribution<double> noise(0, 0.02);
    std::vector<Eigen::VectorXd> measured, model;
    for (const auto& [t0, seconds] : std::vector<std::pair<double, double>>{{0.0, 12.0}, {20.0, 7.0}}) {
      const auto n = static_cast<Eigen::Index>(seconds / c.dt);
      Eigen::VectorXd m(n), p(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        const double t = t0 + i * c.dt;
        p(i) = signal(t);
        m(i) = signal(t - c.delay) + noise(rng);  // the measurement lags the model by delay
      }
      measured.push_back(m);
      model.push_back(p);
    }
    const double lag = torque_lag(measured, model, c.dt, 0.1);
    EXPECT_NEAR(lag, c.delay, 0.0002) << "dt " << c.dt << " delay " << c.delay;
  }
}

TEST(DiagnoseLag, TorqueLagIsNaNForTooShortSeriesAndStaysInTheBound) {
  EXPECT_TRUE(std::isnan(torque_lag({Eigen::VectorXd::Ones(20)}, {Eigen::VectorXd::Ones(20)}, 0.01, 0.1)));
  // A delay beyond the search bound ends at the bound.
  const BandLimited signal(8, 20, 0.1, 1.0);  // R(tau) decreasing over [0, 0.25] s
  const double dt = 0.01;
  Eigen::VectorXd m(3000), p(3000);
  for (int i = 0; i < 3000; ++i) p(i) = signal(i * dt), m(i) = signal(i * dt - 0.25);
  const double lag = torque_lag({m}, {p}, dt, 0.1);
  EXPECT_LE(std::abs(lag), 0.1 + 1e-12);
  EXPECT_NEAR(lag, 0.1, 1e-6);
}

TEST(DiagnoseLag, ResidualVelocityCrossCorrelationPeak) {
  // r(t) = -b v(t - d) + noise: the peak at +d with correlation -1 / sqrt(1 + noise / signal).
  const BandLimited velocity(21, 25, 0.1, 4.0);
  const double dt = 0.002, delay = 0.0213, b = 0.3, sigma = 0.05;
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0, sigma);
  const Eigen::Index n = 20000;
  Eigen::VectorXd r(n), v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    v(i) = velocity(i * dt);
    r(i) = -b * velocity(i * dt - delay) + noise(rng);
  }
  const double var_v = (v.array() - v.mean()).square().mean();
  const double expected = -1 / std::sqrt(1 + sigma * sigma / (b * b * var_v));
  const auto peak = cross_correlation_peak({r}, {v}, dt, 0.1);
  EXPECT_NEAR(peak.lag, delay, 0.0005);
  EXPECT_NEAR(peak.correlation, expected, 0.005);
}

// --- Effective sample size --------------------------------------------------------------------

TEST(DiagnoseStatistics, EffectiveSampleSizeOfAr1) {
  for (const double a : {0.0, 0.5, 0.8, 0.9}) {
    std::mt19937 rng(static_cast<unsigned>(100 * a) + 1);
    std::vector<Eigen::VectorXd> pieces;
    Eigen::Index n = 0;
    for (int p = 0; p < 4; ++p) {
      pieces.push_back(ar1(rng, 50000, a, 1.3));
      n += 50000;
    }
    const double expected = static_cast<double>(n) * (1 - a) / (1 + a);
    const double got = effective_sample_size(pieces);
    EXPECT_NEAR(got / expected, 1, 0.15) << "a = " << a;
    EXPECT_LE(got, static_cast<double>(n));
  }
}

TEST(DiagnoseStatistics, QuantileInterpolatesOrderStatistics) {
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 0.8), 3.4);  // position 2.4 of 1 2 3 4
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 0), 1);
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 1), 4);
  EXPECT_TRUE(std::isnan(quantile({}, 0.5)));
}

// --- Localize: Coulomb residual ---------------------------------------------------------------

constexpr double kCoulomb = 0.05;

std::vector<ResidualSeries> coulomb_series(unsigned seed, double ar, double sigma, int trajectories = 3,
                                           double seconds = 40) {
  const double dt = 0.01;
  const Motion motion{1.0, 2 * pi * 0.25, 0.3};
  std::mt19937 rng(seed);
  std::vector<ResidualSeries> out;
  for (int k = 0; k < trajectories; ++k) {
    const int n = static_cast<int>(seconds / dt);
    const Eigen::VectorXd noise = ar1(rng, n, ar, sigma);
    out.push_back(make_series("C" + std::to_string(k), 100.0 * k, n, dt, {motion}, [&](int i, Eigen::Index, double t) {
      return kCoulomb * (motion.qd(t) > 0 ? 1 : -1) + noise(i);
    }));
  }
  return out;
}

TEST(DiagnoseLocalize, CoulombResidualGivesTheDirectionStep) {
  const double sigma = 0.01;
  const auto series = coulomb_series(1, 0.0, sigma);
  LocalizeOptions options;
  options.segment_seconds = 8;  // 10.24 s: 0.098 Hz bins resolve the 0.25 Hz square wave
  const Localization loc = localize(series, {"J1"}, options);
  ASSERT_EQ(loc.joints.size(), 1u);
  const JointLocalization& jl = loc.joints[0];
  EXPECT_EQ(loc.samples, 12000);
  EXPECT_EQ(loc.series, 3);

  EXPECT_NEAR(jl.direction_step, kCoulomb, 0.05 * kCoulomb);
  // White noise: the standard error is the textbook one, 0.5 sigma sqrt(1/N+ + 1/N-).
  const RegimeStat& up = regime(jl, "qd > ");
  const RegimeStat& down = regime(jl, "qd < ");
  const double se = 0.5 * sigma * std::sqrt(1.0 / up.samples + 1.0 / down.samples);
  EXPECT_NEAR(jl.direction_step_se / se, 1, 0.15);
  EXPECT_NEAR(up.mean, kCoulomb, 0.002);
  EXPECT_NEAR(down.mean, -kCoulomb, 0.002);
  EXPECT_NEAR(jl.residual_rms, std::sqrt(kCoulomb * kCoulomb + sigma * sigma), 0.001);

  // |r| is the same everywhere: every regime's rms is the overall rms and its SSE share its
  // sample fraction (no regime concentrates the error: the step is the whole story).
  for (const auto& r : jl.regimes) {
    ASSERT_GT(r.samples, 100) << r.regime;
    EXPECT_NEAR(r.rms_ratio, 1, 0.05) << r.regime;
    EXPECT_NEAR(r.sse_share, r.fraction, 0.05 * r.fraction + 0.003) << r.regime;
  }
  EXPECT_NEAR(up.sse_share + down.sse_share, up.fraction + down.fraction, 0.01);

  // A square wave in phase with qd: corr(sign(cos), cos) = (2/pi) / (1/sqrt 2) = 0.9003, reduced
  // by the noise, at zero lag.
  const double expected_corr = (2 / pi) * std::sqrt(2.0) * kCoulomb / std::sqrt(kCoulomb * kCoulomb + sigma * sigma);
  EXPECT_NEAR(jl.velocity_correlation, expected_corr, 0.02);
  EXPECT_NEAR(jl.velocity_lag, 0, 0.01);

  // The square wave's fundamental (8/pi^2 of its power) is at 0.25 Hz, its harmonics at
  // 0.75, 1.25, ... Hz; the white noise is flat to 50 Hz.
  const double df = loc.spectrum.frequency(1);
  EXPECT_NEAR(df, 1 / 10.24, 1e-12);
  EXPECT_NEAR(jl.peak_frequency, 0.25, df);
  const double c2 = kCoulomb * kCoulomb, s2 = sigma * sigma;
  const double below_half = (8 / (pi * pi) * c2 + s2 * 0.5 / 50) / (c2 + s2);
  ASSERT_EQ(jl.band_power_fraction.size(), 4);
  EXPECT_NEAR(jl.band_power_fraction(0), below_half, 0.02);
  EXPECT_NEAR(jl.band_power_fraction.sum(), 1, 1e-9);
  ASSERT_EQ(loc.bands.size(), 4u);
  EXPECT_EQ(loc.bands[0], "[0, 0.5) Hz");
  EXPECT_EQ(loc.bands[3], "[5, 50] Hz");

  EXPECT_NE(jl.summary.find("J1: residual"), std::string::npos) << jl.summary;
  EXPECT_NE(jl.summary.find("below 0.5 Hz"), std::string::npos) << jl.summary;
  EXPECT_NE(jl.summary.find("direction step 0.05"), std::string::npos) << jl.summary;
}

TEST(DiagnoseLocalize, DirectionStepStandardErrorMatchesMonteCarloWithAr1Noise) {
  // AR(1) noise (a = 0.8: N / N_eff = 9): the reported standard error must match the spread of
  // the step over independent realizations (the white-noise formula would be 3x too small).
  const int realizations = 150;
  std::vector<double> steps, ses;
  for (int k = 0; k < realizations; ++k) {
    const auto series = coulomb_series(1000 + static_cast<unsigned>(k), 0.8, 0.02, 1, 60);
    const Localization loc = localize(series, {});
    steps.push_back(loc.joints[0].direction_step);
    ses.push_back(loc.joints[0].direction_step_se);
  }
  const double mean = std::accumulate(steps.begin(), steps.end(), 0.0) / realizations;
  double var = 0;
  for (double s : steps) var += (s - mean) * (s - mean);
  const double sd = std::sqrt(var / (realizations - 1));
  const double se = std::accumulate(ses.begin(), ses.end(), 0.0) / realizations;
  EXPECT_NEAR(mean, kCoulomb, 3 * sd / std::sqrt(realizations) + 1e-4);
  EXPECT_NEAR(se / sd, 1, 0.2) << "reported " << se << ", Monte Carlo " << sd;
}

// --- Localize: regimes against direct masks ---------------------------------------------------

TEST(DiagnoseLocalize, RegimeStatisticsMatchDirectlyComputedMasks) {
  const double dt = 0.01;
  // Two trajectories, two joints; each starts and ends at a velocity extreme (so every zero
  // crossing inside is a detected reversal), with phases keeping crossings off the grid; and a
  // slow creep.
  const std::vector<Motion> motion_a{{0.8, 2 * pi * 0.3, 0.1}, {0.5, 2 * pi * 0.45, 3.0}};
  const std::vector<Motion> motion_b{{1.1, 2 * pi * 0.2, 0.05}, {0.4, 2 * pi * 0.6, 2.9}};
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0, 0.01);
  auto residual = [&](const std::vector<Motion>& m) {
    return [&, m](int, Eigen::Index j, double t) {
      const Motion& mj = m[static_cast<std::size_t>(j)];
      return 0.1 * mj.q(t) + 0.02 * std::sin(3 * t) + 0.004 * mj.qdd(t) + noise(rng);
    };
  };
  std::vector<ResidualSeries> series;
  series.push_back(make_series("A", 0.0, static_cast<int>(10.0 / dt), dt, motion_a, residual(motion_a)));
  series.push_back(make_series("B", 50.0, static_cast<int>(15.0 / dt), dt, motion_b, residual(motion_b)));
  // A slow creep (|qd| <= 0.015 < v0): every sample slow, so in the reversal regime, none moving.
  const std::vector<Motion> motion_c{{0.01, 1.5, 0.2}, {0.005, 2.5, 1.0}};
  series.push_back(make_series("C", 80.0, static_cast<int>(4.0 / dt), dt, motion_c, residual(motion_c)));
  const LocalizeOptions options;
  const Localization loc = localize(series, {"shoulder", "elbow"}, options);
  ASSERT_EQ(loc.joints.size(), 2u);

  for (int j = 0; j < 2; ++j) {
    // The pooled columns and the masks, straight from the analytic motion.
    std::vector<double> r, q, abs_qdd;
    std::vector<char> reversal, up, down;
    for (std::size_t s = 0; s < series.size(); ++s) {
      const Motion& m = (s == 0 ? motion_a : s == 1 ? motion_b : motion_c)[static_cast<std::size_t>(j)];
      const auto& sr = series[s];
      const double t_first = sr.time(0), t_last = sr.time(sr.time.size() - 1);
      // Zero crossings of qd = A w cos(w t + phi): w t + phi = pi/2 + k pi.
      std::vector<double> crossings;
      for (int k = -2; k < 100; ++k) {
        const double tc = (pi / 2 + k * pi - m.phase) / m.omega;
        if (tc > t_first && tc < t_last) crossings.push_back(tc);
      }
      for (Eigen::Index i = 0; i < sr.time.size(); ++i) {
        const double t = sr.time(i), v = m.qd(t);
        r.push_back(sr.tau_measured(i, j) - sr.tau_model(i, j));
        q.push_back(m.q(t));
        abs_qdd.push_back(std::abs(m.qdd(t)));
        bool near = std::abs(v) <= options.direction_velocity;
        for (double tc : crossings) near = near || std::abs(t - tc) <= options.reversal_window;
        reversal.push_back(near);
        up.push_back(v > options.direction_velocity);
        down.push_back(v < -options.direction_velocity);
      }
    }
    const auto n = r.size();
    auto order_stat = [](std::vector<double> v, double p) {
      std::sort(v.begin(), v.end());
      const double h = p * static_cast<double>(v.size() - 1);
      const auto lo = static_cast<std::size_t>(h);
      return lo + 1 < v.size() ? v[lo] + (h - static_cast<double>(lo)) * (v[lo + 1] - v[lo]) : v[lo];
    };
    const double threshold = order_stat(abs_qdd, 0.8);
    std::vector<char> high(n);
    for (std::size_t i = 0; i < n; ++i) high[i] = abs_qdd[i] > threshold;
    double sse = 0;
    for (double x : r) sse += x * x;
    const double rms = std::sqrt(sse / static_cast<double>(n));

    const JointLocalization& jl = loc.joints[static_cast<std::size_t>(j)];
    EXPECT_NEAR(jl.residual_rms, rms, 1e-12);
    auto check = [&](const RegimeStat& got, const std::vector<char>& mask, const std::string& what) {
      int samples = 0;
      double sum = 0, sq = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (mask[i]) ++samples, sum += r[i], sq += r[i] * r[i];
      EXPECT_EQ(got.samples, samples) << what;
      EXPECT_NEAR(got.fraction, static_cast<double>(samples) / n, 1e-12) << what;
      EXPECT_NEAR(got.mean, sum / samples, 1e-12) << what;
      EXPECT_NEAR(got.rms, std::sqrt(sq / samples), 1e-12) << what;
      EXPECT_NEAR(got.rms_ratio, std::sqrt(sq / samples) / rms, 1e-10) << what;
      EXPECT_NEAR(got.sse_share, sq / sse, 1e-12) << what;
    };
    ASSERT_EQ(jl.regimes.size(), 8u);
    EXPECT_EQ(jl.regimes[0].regime, "velocity reversal");
    check(jl.regimes[0], reversal, "reversal");
    check(jl.regimes[1], high, "high acceleration");
    EXPECT_NEAR(jl.regimes[1].fraction, 0.2, 1.0 / n + 1e-12);
    double band_samples = 0;
    for (int b = 0; b < 4; ++b) {
      const double lo = order_stat(q, b / 4.0), hi = order_stat(q, (b + 1) / 4.0);
      std::vector<char> band(n);
      for (std::size_t i = 0; i < n; ++i) band[i] = q[i] >= lo && (q[i] < hi || (b == 3 && q[i] <= hi));
      check(jl.regimes[static_cast<std::size_t>(2 + b)], band, "band " + std::to_string(b));
      EXPECT_NEAR(jl.regimes[static_cast<std::size_t>(2 + b)].fraction, 0.25, 2.0 / n);
      EXPECT_NE(jl.regimes[static_cast<std::size_t>(2 + b)].regime.find(" rad ("), std::string::npos);
      EXPECT_NE(jl.regimes[static_cast<std::size_t>(2 + b)].regime.find(" deg)"), std::string::npos);
      band_samples += jl.regimes[static_cast<std::size_t>(2 + b)].samples;
    }
    EXPECT_EQ(band_samples, static_cast<double>(n));
    check(jl.regimes[6], up, "qd > v0");
    check(jl.regimes[7], down, "qd < -v0");
    EXPECT_GE(jl.regimes[0].samples, 400);  // at least the creep
  }
}

TEST(DiagnoseLocalize, BandFractionsOfBinCentredTones) {
  // Four tones on bin centres (0.0977 Hz bins), one per default band: fraction = a_i^2 / sum.
  const double dt = 0.01, df = 1 / (1024 * dt);
  const std::vector<std::pair<int, double>> tones{{2, 0.3}, {10, 0.2}, {31, 0.1}, {82, 0.05}};
  const Motion motion{0.5, 2 * pi * 0.37, 0.2};
  auto series = make_series("T", 0, 30000, dt, {motion}, [&](int, Eigen::Index, double t) {
    double s = 0;
    for (const auto& [bin, a] : tones) s += a * std::sin(2 * pi * bin * df * t + bin);
    return s;
  });
  LocalizeOptions options;
  options.segment_seconds = 10;  // 1024 samples
  const Localization loc = localize({series}, {}, options);
  double total = 0;
  for (const auto& tone : tones) total += tone.second * tone.second;
  const auto& jl = loc.joints[0];
  ASSERT_EQ(jl.band_power_fraction.size(), 4);
  for (std::size_t b = 0; b < tones.size(); ++b)
    EXPECT_NEAR(jl.band_power_fraction(static_cast<Eigen::Index>(b)), tones[b].second * tones[b].second / total, 0.005)
        << loc.bands[b];
  EXPECT_NEAR(jl.peak_frequency, 2 * df, 0.01);
  EXPECT_EQ(jl.name, "joint 1");

  // Other edges: a band starting above 0 leaves the power below it out.
  options.band_edges = {0.5, 5};
  const Localization partial = localize({series}, {}, options);
  EXPECT_NEAR(partial.joints[0].band_power_fraction.sum(), 1 - tones[0].second * tones[0].second / total, 0.005);
}

TEST(DiagnoseLocalize, TorqueLagThroughTheStage) {
  // A measurement 4 ms behind the model on every joint: the stage reports +4 ms.
  const double dt = 0.002, delay = 0.004;
  const BandLimited torque(31, 20, 0.1, 5.0);
  const std::vector<Motion> motion{{0.6, 2 * pi * 0.2, 0.3}, {0.3, 2 * pi * 0.35, 1.0}};
  auto s = make_series("L", 0, 10000, dt, motion, [](int, Eigen::Index, double) { return 0.0; });
  for (Eigen::Index i = 0; i < s.time.size(); ++i)
    for (Eigen::Index j = 0; j < 2; ++j) {
      s.tau_model(i, j) = torque(s.time(i) + 3.0 * j);
      s.tau_measured(i, j) = torque(s.time(i) + 3.0 * j - delay);
    }
  const Localization loc = localize({s}, {"a", "b"});
  for (const auto& jl : loc.joints) {
    EXPECT_NEAR(jl.torque_lag, delay, 0.0002) << jl.name;
    EXPECT_NE(jl.summary.find("measured torque lags the model by 4.0 ms"), std::string::npos) << jl.summary;
  }
}

TEST(DiagnoseLocalize, FrictionMisfitBiasesTheTorqueLagButNotTheAdjustedOne) {
  // tau = 2 sin q + 0.3 qdd delayed by 3 ms in the measurement, plus a Coulomb (joint 1) or
  // viscous (joint 2) misfit: d tau / dt = qd (2 cos q - 0.3 w^2) correlates with both, so the
  // plain lag is pulled by tens of ms; with offset, sign(qd) and qd fitted at every shift the
  // delay comes back.
  const double dt = 0.005, delay = 0.003;
  std::mt19937 rng(12);
  std::normal_distribution<double> noise(0, 0.005);
  std::vector<ResidualSeries> series;
  for (int k = 0; k < 3; ++k) {
    const std::vector<Motion> motion{{1.0, 2 * pi * (0.2 + 0.05 * k), 0.3}, {1.0, 2 * pi * (0.3 + 0.05 * k), 1.3}};
    auto s =
        make_series("F" + std::to_string(k), 40.0 * k, 6000, dt, motion, [](int, Eigen::Index, double) { return 0.0; });
    for (Eigen::Index i = 0; i < s.time.size(); ++i)
      for (Eigen::Index j = 0; j < 2; ++j) {
        const Motion& m = motion[static_cast<std::size_t>(j)];
        const double t = s.time(i), late = t - delay;
        const double friction = j == 0 ? 0.05 * (m.qd(t) > 0 ? 1 : -1) : 0.02 * m.qd(t);
        s.tau_measured(i, j) = 2 * std::sin(m.q(late)) + 0.3 * m.qdd(late) + 0.1 * static_cast<double>(j) + friction +
                               noise(rng);  // the model's torque (make_series), delayed
      }
    series.push_back(s);
  }
  const Localization loc = localize(series, {"coulomb", "viscous"});
  for (const auto& jl : loc.joints) {
    EXPECT_NEAR(jl.torque_lag_adjusted, delay, 0.0003) << jl.name;
    EXPECT_GT(std::abs(jl.torque_lag - delay), 0.005) << jl.name << ": the plain lag is confounded";
  }
  // The adjustment alone, on the building block: no friction, no bias either way.
  std::vector<Eigen::VectorXd> measured, model;
  std::vector<Eigen::MatrixXd> nuisance;
  for (const auto& s : series) {
    measured.emplace_back(s.tau_measured.col(1) - 0.02 * s.qd.col(1));
    model.emplace_back(s.tau_model.col(1));
    Eigen::MatrixXd x(s.time.size(), 2);
    x.col(0) = s.qd.col(1);
    x.col(1).setOnes();
    nuisance.push_back(x);
  }
  EXPECT_NEAR(torque_lag(measured, model, dt, 0.1), delay, 0.0002);
  EXPECT_NEAR(torque_lag(measured, model, dt, 0.1, nuisance), delay, 0.0003);
  nuisance.pop_back();
  EXPECT_THROW(torque_lag(measured, model, dt, 0.1, nuisance), std::invalid_argument);
}

TEST(DiagnoseLocalize, RejectsInconsistentInput) {
  const Motion m{0.5, 1.0, 0.1};
  auto good = make_series("G", 0, 500, 0.01, {m, m}, [](int, Eigen::Index, double) { return 0.01; });
  EXPECT_NO_THROW(localize({good}, {"a", "b"}));
  EXPECT_THROW(localize({good}, {"a"}), std::invalid_argument);
  EXPECT_THROW(localize({}, {}), std::invalid_argument);
  auto bad = good;
  bad.tau_model.conservativeResize(499, 2);
  EXPECT_THROW(localize({bad}, {}), std::invalid_argument);
  bad = good;
  bad.time(200) += 0.005;  // off the grid
  EXPECT_THROW(localize({bad}, {}), std::invalid_argument);
  bad = good;
  bad.interval = 0.02;
  EXPECT_THROW(localize({good, bad}, {}), std::invalid_argument);
  bad = good;
  bad.qd(3, 1) = std::nan("");
  EXPECT_THROW(localize({bad}, {}), std::invalid_argument);
  LocalizeOptions options;
  options.band_edges = {0, 2, 1};
  EXPECT_THROW(localize({good}, {}, options), std::invalid_argument);
}

// --- Report ---------------------------------------------------------------------------------

TEST(DiagnoseLocalizeReport, MarkdownHasOneRowPerJoint) {
  auto series = coulomb_series(4, 0.0, 0.01, 2, 20);
  // Three joints: the same motion, scaled residuals.
  for (auto& s : series) {
    for (auto* m : {&s.q, &s.qd, &s.qdd, &s.tau_measured, &s.tau_model}) *m = m->replicate(1, 3).eval();
    for (int j = 1; j < 3; ++j)
      s.tau_measured.col(j) = s.tau_model.col(j) + (j + 1) * (s.tau_measured.col(0) - s.tau_model.col(0));
  }
  const std::vector<std::string> names{"base | yaw", "shoulder", "elbow"};
  const Localization loc = localize(series, names);
  const std::string md = localization_markdown(loc, {"figures/x_residual_velocity.svg"});

  // The first table: header, alignment row, one row per joint, in order.
  std::istringstream in(md);
  std::string line;
  std::vector<std::string> rows;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.rfind("|", 0) == 0) {
      inside = true;
      rows.push_back(line);
    } else if (inside) {
      break;
    }
  }
  ASSERT_EQ(rows.size(), 2 + names.size());
  EXPECT_EQ(rows[2].rfind("| base \\| yaw |", 0), 0u) << rows[2];  // '|' escaped
  EXPECT_EQ(rows[3].rfind("| shoulder |", 0), 0u);
  EXPECT_EQ(rows[4].rfind("| elbow |", 0), 0u);
  for (std::size_t i = 0; i < rows.size(); ++i)
    EXPECT_EQ(i == 1 ? count(rows[i], "|") : count(rows[i], " |"), i == 1 ? 13u : 12u) << rows[i];
  // The summaries, the figure, the regime rows (8 per joint).
  for (const auto& name : names) EXPECT_NE(md.find("- " + name + ": residual"), std::string::npos);
  EXPECT_NE(md.find("![Residual vs joint velocity (friction signature)](figures/x_residual_velocity.svg)"),
            std::string::npos);
  EXPECT_EQ(count(md, "| velocity reversal |"), names.size());
  EXPECT_EQ(count(md, "| high acceleration ("), names.size());
  EXPECT_NE(md.find("| [5, 50] Hz |"), std::string::npos);
  // The residual rms column: the j-th joint's residual is (j + 1) times the first's.
  EXPECT_NEAR(loc.joints[2].residual_rms / loc.joints[0].residual_rms, 3, 1e-9);
}

TEST(DiagnoseLocalizeReport, FiguresAreXmlWithOnePanelPerJoint) {
  auto series = coulomb_series(6, 0.0, 0.01, 3, 40);  // 12000 samples: the scatter is decimated
  for (auto& s : series) {
    for (auto* m : {&s.q, &s.qd, &s.qdd, &s.tau_measured, &s.tau_model}) *m = m->replicate(1, 2).eval();
    s.tau_measured.col(1) = s.tau_model.col(1) + 0.5 * (s.tau_measured.col(0) - s.tau_model.col(0));
  }
  // A second piece of trajectory C1 (the time figure draws both, a gap between them).
  auto piece = series[1];
  piece.time.array() += 45;
  series.push_back(piece);
  const Localization loc = localize(series, {"J1", "J2"});

  const fs::path dir = fs::temp_directory_path() / ("symoro_localize_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  LocalizationFigureOptions options;
  options.time_trajectory = "C1";
  const auto files = write_localization_figures(series, loc, dir / "figures", "clie", options);
  ASSERT_EQ(files, (std::vector<std::string>{"clie_residual_velocity.svg", "clie_residual_spectrum.svg",
                                             "clie_residual_time.svg"}));
  for (const auto& name : files) {
    ASSERT_TRUE(fs::exists(dir / "figures" / name)) << name;
    const std::string svg = read_text(dir / "figures" / name);
    XmlCheck xml(svg);
    EXPECT_EQ(xml.run(), "") << name;
    EXPECT_GT(xml.elements, 10) << name;
    EXPECT_EQ(svg.rfind("<svg ", 0), 0u) << name;
    const auto ps = panels(svg);
    ASSERT_EQ(ps.size(), 2u) << name;
    if (name == "clie_residual_velocity.svg")
      for (const auto& p : ps) {
        const auto markers = count(p, "class=\"marker\"");
        EXPECT_LE(markers, 2000u);
        EXPECT_GE(markers, 1500u);  // 16000 samples at stride 8
      }
    if (name == "clie_residual_spectrum.svg")
      for (const auto& p : ps) {
        EXPECT_EQ(count(p, "<polyline"), 2u);  // residual and measured
        EXPECT_NE(p.find("log10 PSD"), std::string::npos);
      }
    if (name == "clie_residual_time.svg") {
      for (const auto& p : ps) EXPECT_EQ(count(p, "<polyline"), 2u);  // two pieces
    }
  }
  // No temporary files left behind.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir / "figures")) {
    (void)e;
    ++entries;
  }
  EXPECT_EQ(entries, 3);
  fs::remove_all(dir);
}

}  // namespace
