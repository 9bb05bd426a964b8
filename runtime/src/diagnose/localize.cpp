#include "symoro/detail/numbers.hpp"
#include "symoro/diagnose/localize.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include <Eigen/QR>
#include <fmt/format.h>
#include <unsupported/Eigen/FFT>

namespace symoro::diagnose {

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double deg_per_rad = 180 / pi;
using symoro::detail::nan;

using Index = Eigen::Index;

// The smallest power of two >= n (n > 0), and the largest one <= n (0 for n < 1).
long long pow2_at_least(double n) {
  long long p = 1;
  while (static_cast<double>(p) < n && p < (1LL << 40)) p <<= 1;
  return p;
}
long long pow2_at_most(long long n) {
  if (n < 1) return 0;
  long long p = 1;
  while (p * 2 <= n) p <<= 1;
  return p;
}

// Catmull-Rom cubic through p(i - 1) .. p(i + 2) at x = i + u (0 <= u < 1): exact at the
// samples, C1, and third-order accurate for a band-limited signal well below Nyquist.
double catmull_rom(const Eigen::VectorXd& p, double x) {
  const auto i = static_cast<Index>(std::floor(x));
  const double u = x - static_cast<double>(i);
  const double p0 = p(i - 1), p1 = p(i), p2 = p(i + 1), p3 = p(i + 2);
  return p1 + 0.5 * u * (p2 - p0 + u * (2 * p0 - 5 * p1 + 4 * p2 - p3 + u * (3 * (p1 - p2) + p3 - p0)));
}

// The lag search's integer range +-K (K = floor(max_lag / interval)) and its fractional bound.
struct LagRange {
  double bound = 0;  // max_lag / interval, samples
  Index k = 0;
  Index margin = 0;  // samples left out at each end of a piece: every shift stays inside it
};

LagRange lag_range(double interval, double max_lag) {
  if (!(interval > 0) || !(max_lag >= 0) || !std::isfinite(max_lag))
    throw std::invalid_argument("lag search: interval must be > 0 and max_lag finite and >= 0");
  LagRange r;
  r.bound = max_lag / interval;
  r.k = static_cast<Index>(std::floor(r.bound + 1e-9));
  r.bound = std::max(r.bound, static_cast<double>(r.k));
  r.margin = r.k + 3;
  return r;
}

void check_pairs(const std::vector<Eigen::VectorXd>& a, const std::vector<Eigen::VectorXd>& b, const char* what) {
  if (a.size() != b.size()) throw std::invalid_argument(fmt::format("{}: {} vs {} pieces", what, a.size(), b.size()));
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size())
      throw std::invalid_argument(fmt::format("{}: piece {} has {} vs {} samples", what, i, a[i].size(), b[i].size()));
}

// Golden-section minimum of f on [a, b].
template <class F>
double golden_minimum(F f, double a, double b) {
  const double g = (std::sqrt(5.0) - 1) / 2;
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int it = 0; it < 60 && b - a > 1e-7; ++it) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - g * (b - a), fc = f(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + g * (b - a), fd = f(d);
    }
  }
  return (a + b) / 2;
}

// --- Formatting for the summary -------------------------------------------------------------

// Three significant digits in fixed notation ("0.0412", "12.3", "150").
std::string sig3(double v) {
  if (!std::isfinite(v)) return "n/a";
  if (v == 0) return "0";
  const int decimals = std::clamp(2 - static_cast<int>(std::floor(std::log10(std::abs(v)))), 0, 9);
  return fmt::format("{:.{}f}", v, decimals);
}

std::string percent(double fraction) {
  return std::isfinite(fraction) ? fmt::format("{:.0f}", 100 * fraction) : std::string("n/a");
}

// A band edge as written by people: "0.5", "2", "500".
std::string edge_text(double hz) { return fmt::format("{}", hz); }

// --- Regimes ------------------------------------------------------------------------------

// Samples within +-window of a velocity reversal, or slow (|qd| <= v0). A reversal is a change
// of the definite sign (|qd| > v0) of qd; its instants are the zero crossings of qd (linear
// interpolation) between the last sample of the old sign and the first of the new one. With v0
// as hysteresis, noise chattering around zero during a slow phase or a hold adds no reversals
// (those samples are slow anyway).
std::vector<char> reversal_mask(const Eigen::VectorXd& t, const Eigen::VectorXd& v, double window, double v0) {
  const Index n = v.size();
  std::vector<char> mask(static_cast<std::size_t>(n), 0);
  auto mark = [&](double tc, Index k) {
    for (Index i = k; i >= 0 && t(i) >= tc - window; --i)
      if (std::abs(t(i) - tc) <= window) mask[static_cast<std::size_t>(i)] = 1;
    for (Index i = k + 1; i < n && t(i) <= tc + window; ++i)
      if (std::abs(t(i) - tc) <= window) mask[static_cast<std::size_t>(i)] = 1;
  };
  int state = 0;
  Index last = -1;
  for (Index i = 0; i < n; ++i) {
    if (std::abs(v(i)) <= v0) mask[static_cast<std::size_t>(i)] = 1;
    const int s = v(i) > v0 ? 1 : v(i) < -v0 ? -1 : 0;
    if (s == 0) continue;
    if (state != 0 && s != state)
      for (Index k = last; k < i; ++k) {
        if (v(k) == 0) {
          mark(t(k), k);
        } else if (v(k) * v(k + 1) < 0) {
          const double u = v(k) / (v(k) - v(k + 1));
          mark(t(k) + u * (t(k + 1) - t(k)), k);
        }
      }
    state = s;
    last = i;
  }
  return mask;
}

RegimeStat regime_stat(std::string name, const Eigen::VectorXd& r, const std::vector<char>& mask, double sse,
                       double rms) {
  RegimeStat s;
  s.regime = std::move(name);
  double sum = 0, sq = 0;
  for (Index i = 0; i < r.size(); ++i)
    if (mask[static_cast<std::size_t>(i)]) {
      ++s.samples;
      sum += r(i);
      sq += r(i) * r(i);
    }
  const auto n = static_cast<double>(r.size());
  s.fraction = n > 0 ? s.samples / n : 0;
  s.mean = s.samples > 0 ? sum / s.samples : nan;
  s.rms = s.samples > 0 ? std::sqrt(sq / s.samples) : nan;
  s.rms_ratio = rms > 0 ? s.rms / rms : nan;
  s.sse_share = sse > 0 ? sq / sse : (s.samples > 0 ? nan : 0);
  return s;
}

// Pooled columns of one joint, in series order, with where each series starts.
struct Pooled {
  Eigen::VectorXd t, q, qd, qdd, r, tau;
  std::vector<Index> start;  // start.size() == series + 1
  Eigen::VectorXd piece(const Eigen::VectorXd& all, std::size_t s) const {
    return all.segment(start[s], start[s + 1] - start[s]);
  }
};

Pooled pool(const std::vector<const ResidualSeries*>& series, Index j, Index total) {
  Pooled p;
  for (auto* v : {&p.t, &p.q, &p.qd, &p.qdd, &p.r, &p.tau}) v->resize(total);
  Index at = 0;
  for (const auto* s : series) {
    p.start.push_back(at);
    const Index n = s->time.size();
    p.t.segment(at, n) = s->time;
    p.q.segment(at, n) = s->q.col(j);
    p.qd.segment(at, n) = s->qd.col(j);
    p.qdd.segment(at, n) = s->qdd.col(j);
    p.tau.segment(at, n) = s->tau_measured.col(j);
    p.r.segment(at, n) = s->tau_measured.col(j) - s->tau_model.col(j);
    at += n;
  }
  p.start.push_back(at);
  return p;
}

void check_options(const LocalizeOptions& options) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("localize: " + what); };
  if (!(options.reversal_window >= 0) || !std::isfinite(options.reversal_window))
    bad("reversal_window must be finite and >= 0");
  if (!(options.direction_velocity >= 0) || !std::isfinite(options.direction_velocity))
    bad("direction_velocity must be finite and >= 0");
  if (!(options.high_acceleration_quantile > 0 && options.high_acceleration_quantile < 1))
    bad("high_acceleration_quantile must be in (0, 1)");
  if (options.position_bands < 1) bad("position_bands must be >= 1");
  if (options.band_edges.empty()) bad("band_edges must not be empty");
  for (std::size_t i = 0; i < options.band_edges.size(); ++i)
    if (!std::isfinite(options.band_edges[i]) || options.band_edges[i] < 0 ||
        (i > 0 && options.band_edges[i] <= options.band_edges[i - 1]))
      bad("band_edges must be finite, >= 0 and strictly ascending");
  if (!(options.segment_seconds > 0) || !std::isfinite(options.segment_seconds))
    bad("segment_seconds must be finite and > 0");
  if (!(options.max_lag >= 0) || !std::isfinite(options.max_lag)) bad("max_lag must be finite and >= 0");
}

// The series with samples, after checking shapes, grids and values.
std::vector<const ResidualSeries*> checked_series(const std::vector<ResidualSeries>& series, Index& joints,
                                                  double& interval) {
  std::vector<const ResidualSeries*> used;
  joints = -1;
  interval = 0;
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const std::string who = fmt::format("localize: series {} ('{}')", k, s.name);
    const Index n = s.time.size();
    const Index j = s.tau_measured.cols();
    for (const Eigen::MatrixXd* m : {&s.q, &s.qd, &s.qdd, &s.tau_measured, &s.tau_model})
      if (m->rows() != n || m->cols() != j)
        throw std::invalid_argument(who + ": q, qd, qdd, tau_measured, tau_model must all be samples x joints");
    if (n == 0) continue;
    if (j < 1) throw std::invalid_argument(who + ": no joints");
    if (!(s.interval > 0) || !std::isfinite(s.interval)) throw std::invalid_argument(who + ": interval must be > 0");
    if (joints < 0) {
      joints = j;
      interval = s.interval;
    }
    if (j != joints) throw std::invalid_argument(who + ": joint count differs from the first series");
    if (std::abs(s.interval - interval) > 1e-9 * interval)
      throw std::invalid_argument(who + ": interval differs from the first series (spectra need one grid)");
    for (Index i = 1; i < n; ++i)
      if (!(std::abs(s.time(i) - s.time(i - 1) - interval) <= 1e-3 * interval))
        throw std::invalid_argument(fmt::format("{}: samples {} and {} are not one interval apart", who, i - 1, i));
    if (!s.time.allFinite() || !s.q.allFinite() || !s.qd.allFinite() || !s.qdd.allFinite() ||
        !s.tau_measured.allFinite() || !s.tau_model.allFinite())
      throw std::invalid_argument(who + ": a value is not finite");
    used.push_back(&s);
  }
  if (used.empty()) throw std::invalid_argument("localize: no series with samples");
  return used;
}

std::string band_phrase(const std::vector<double>& edges, std::size_t b) {
  const bool last = b + 1 == edges.size();
  if (last) return edges[b] == 0 ? "at all frequencies" : "above " + edge_text(edges[b]) + " Hz";
  if (edges[b] == 0) return "below " + edge_text(edges[b + 1]) + " Hz";
  return "in " + edge_text(edges[b]) + "-" + edge_text(edges[b + 1]) + " Hz";
}

std::string joint_summary(const JointLocalization& jl, const std::vector<double>& edges, double max_lag) {
  std::string out = fmt::format("{}: residual {} N m rms ({} % of torque rms)", jl.name, sig3(jl.residual_rms),
                                percent(jl.torque_rms > 0 ? jl.residual_rms / jl.torque_rms : nan));
  if (!jl.regimes.empty()) {
    const auto& rev = jl.regimes.front();
    out += fmt::format("; {} % of it at velocity reversals ({} % of samples)", percent(rev.sse_share),
                       percent(rev.fraction));
  }
  if (std::isfinite(jl.direction_step)) {
    // The step with as many decimals as show its standard error to two significant digits.
    const int decimals = std::isfinite(jl.direction_step_se) && jl.direction_step_se > 0
                             ? std::clamp(1 - static_cast<int>(std::floor(std::log10(jl.direction_step_se))), 0, 9)
                             : 4;
    out += fmt::format("; direction step {:.{}f} N m +- {:.{}f}", jl.direction_step, decimals, jl.direction_step_se,
                       decimals);
  } else {
    out += "; no direction step (too few samples moving each way)";
  }
  if (jl.band_power_fraction.size() > 0 && jl.band_power_fraction.allFinite()) {
    Index b = 0;
    jl.band_power_fraction.maxCoeff(&b);
    out += fmt::format("; {} % of power {}; peak at {} Hz", percent(jl.band_power_fraction(b)),
                       band_phrase(edges, static_cast<std::size_t>(b)), sig3(jl.peak_frequency));
  } else {
    out += "; no spectrum";
  }
  if (std::isfinite(jl.torque_lag)) {
    out += fmt::format("; measured torque {} the model by {:.1f} ms", jl.torque_lag >= 0 ? "lags" : "leads",
                       std::abs(jl.torque_lag) * 1000);
    if (std::abs(jl.torque_lag) >= max_lag * (1 - 1e-6) && max_lag > 0) out += " (the search bound)";
    if (std::isfinite(jl.torque_lag_adjusted))
      out += fmt::format(" ({:.1f} ms with the residual's friction-like part removed)", jl.torque_lag_adjusted * 1000);
  } else {
    out += "; torque lag n/a (series too short)";
  }
  return out;
}

}  // namespace

// --- Building blocks ------------------------------------------------------------------------

double quantile(std::vector<double> values, double p) {
  if (values.empty()) return nan;
  p = std::clamp(p, 0.0, 1.0);
  const double h = p * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo), values.end());
  const double a = values[lo];
  if (lo + 1 >= values.size()) return a;
  const double b = *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(lo) + 1, values.end());
  return a + (h - static_cast<double>(lo)) * (b - a);
}

int welch_segment_length(double interval, double segment_seconds) {
  if (!(interval > 0) || !(segment_seconds > 0) || !std::isfinite(segment_seconds / interval))
    throw std::invalid_argument("welch_segment_length: interval and segment_seconds must be > 0");
  const long long n = pow2_at_least(std::max(4.0, segment_seconds / interval * (1 - 1e-12)));
  if (n > (1LL << 30)) throw std::invalid_argument("welch_segment_length: segment too long");
  return static_cast<int>(n);
}

Psd welch(const std::vector<Eigen::MatrixXd>& pieces, double interval, int segment_length) {
  if (!(interval > 0) || !std::isfinite(interval)) throw std::invalid_argument("welch: interval must be > 0");
  if (segment_length < 4 || segment_length % 2 != 0)
    throw std::invalid_argument("welch: segment_length must be even and >= 4");
  const Index columns = pieces.empty() ? 0 : pieces.front().cols();
  for (const auto& p : pieces)
    if (p.cols() != columns) throw std::invalid_argument("welch: pieces have different column counts");
  const Index L = segment_length, F = L / 2 + 1, step = L / 2;

  Psd out;
  out.segment_length = segment_length;
  out.frequency = Eigen::VectorXd::LinSpaced(F, 0, static_cast<double>(F - 1)) / (static_cast<double>(L) * interval);
  Eigen::VectorXd window(L);
  for (Index i = 0; i < L; ++i)
    window(i) = 0.5 - 0.5 * std::cos(2 * pi * static_cast<double>(i) / static_cast<double>(L));
  const double s2 = window.squaredNorm();

  Eigen::MatrixXd power = Eigen::MatrixXd::Zero(F, columns);
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> buffer(static_cast<std::size_t>(L));
  std::vector<std::complex<double>> spectrum;
  for (const auto& p : pieces) {
    const Index n = p.rows();
    if (n < L) continue;
    const Index count = (n - L) / step + 1;
    const Index offset = (n - L - (count - 1) * step) / 2;
    for (Index s = 0; s < count; ++s) {
      const Index start = offset + s * step;
      for (Index c = 0; c < columns; ++c) {
        for (Index i = 0; i < L; ++i) buffer[static_cast<std::size_t>(i)] = p(start + i, c) * window(i);
        fft.fwd(spectrum, buffer);
        for (Index f = 0; f < F; ++f) power(f, c) += std::norm(spectrum[static_cast<std::size_t>(f)]);
      }
    }
    out.segments += static_cast<int>(count);
  }
  if (out.segments == 0) {
    out.power.resize(0, columns);
    out.frequency.resize(0);
    return out;
  }
  // One-sided density: |X|^2 / (fs sum w^2), doubled except at 0 and Nyquist (L even).
  power *= interval / (s2 * out.segments);
  power.middleRows(1, F - 2) *= 2;
  out.power = std::move(power);
  return out;
}

double torque_lag(const std::vector<Eigen::VectorXd>& measured, const std::vector<Eigen::VectorXd>& model,
                  double interval, double max_lag, const std::vector<Eigen::MatrixXd>& nuisance) {
  check_pairs(measured, model, "torque_lag");
  const LagRange range = lag_range(interval, max_lag);
  const Index m = range.margin;
  const bool adjust = !nuisance.empty();
  const Index p = adjust ? nuisance.front().cols() : 0;
  if (adjust) {
    if (nuisance.size() != measured.size()) throw std::invalid_argument("torque_lag: one nuisance matrix per piece");
    for (std::size_t s = 0; s < nuisance.size(); ++s)
      if (nuisance[s].rows() != measured[s].size() || nuisance[s].cols() != p)
        throw std::invalid_argument(fmt::format("torque_lag: nuisance matrix {} is not samples x {}", s, p));
  }
  bool any = false;
  for (const auto& x : measured) any = any || x.size() > 2 * m;
  if (!any) return nan;

  // Every delta is scored on the same samples, so the nuisance fit's normal matrix is one; the
  // cost is |e|^2 - g' G^+ g with g = X' e (the part of e the columns explain, removed).
  Eigen::MatrixXd g_inv;
  if (adjust) {
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(p, p);
    for (std::size_t s = 0; s < measured.size(); ++s) {
      const Index n = measured[s].size();
      if (n <= 2 * m) continue;
      const auto x = nuisance[s].middleRows(m, n - 2 * m);
      gram.noalias() += x.transpose() * x;
    }
    g_inv = gram.completeOrthogonalDecomposition().pseudoInverse();
  }
  Eigen::VectorXd e, g(p);
  auto score = [&](auto&& error_of_piece) {
    double sum = 0;
    g.setZero();
    for (std::size_t s = 0; s < measured.size(); ++s) {
      const Index n = measured[s].size();
      if (n <= 2 * m) continue;
      error_of_piece(s, n, e);
      sum += e.squaredNorm();
      if (adjust) g.noalias() += nuisance[s].middleRows(m, n - 2 * m).transpose() * e;
    }
    return adjust ? sum - g.dot(g_inv * g) : sum;
  };
  auto integer_cost = [&](Index k) {
    return score([&](std::size_t s, Index n, Eigen::VectorXd& out) {
      out = measured[s].segment(m, n - 2 * m) - model[s].segment(m - k, n - 2 * m);
    });
  };
  auto cost = [&](double d) {  // d in samples
    return score([&](std::size_t s, Index n, Eigen::VectorXd& out) {
      out.resize(n - 2 * m);
      for (Index i = m; i < n - m; ++i) out(i - m) = measured[s](i) - catmull_rom(model[s], static_cast<double>(i) - d);
    });
  };
  Index best = 0;
  double best_cost = integer_cost(0);
  for (Index k = -range.k; k <= range.k; ++k) {
    const double c = integer_cost(k);
    if (c < best_cost) best = k, best_cost = c;
  }
  const double lo = std::max(static_cast<double>(best) - 1, -range.bound);
  const double hi = std::min(static_cast<double>(best) + 1, range.bound);
  double d = static_cast<double>(best);
  if (hi > lo) {
    const double refined = golden_minimum(cost, lo, hi);
    if (cost(refined) <= best_cost) d = refined;
  }
  return d * interval;
}

CrossCorrelationPeak cross_correlation_peak(const std::vector<Eigen::VectorXd>& x,
                                            const std::vector<Eigen::VectorXd>& y, double interval, double max_lag) {
  check_pairs(x, y, "cross_correlation_peak");
  const LagRange range = lag_range(interval, max_lag);
  const Index m = range.margin;
  double sx = 0, sy = 0;
  Index total = 0;
  for (std::size_t s = 0; s < x.size(); ++s) sx += x[s].sum(), sy += y[s].sum(), total += x[s].size();
  CrossCorrelationPeak out;
  if (total == 0) return out;
  const double mx = sx / static_cast<double>(total), my = sy / static_cast<double>(total);

  auto correlation = [&](Index k) {
    double xy = 0, xx = 0, yy = 0;
    for (std::size_t s = 0; s < x.size(); ++s) {
      const Index n = x[s].size();
      if (n <= 2 * m) continue;
      const Eigen::ArrayXd a = x[s].segment(m, n - 2 * m).array() - mx;
      const Eigen::ArrayXd b = y[s].segment(m - k, n - 2 * m).array() - my;
      xy += (a * b).sum();
      xx += a.square().sum();
      yy += b.square().sum();
    }
    return xx > 0 && yy > 0 ? xy / std::sqrt(xx * yy) : nan;
  };
  std::vector<double> c;
  for (Index k = -range.k; k <= range.k; ++k) c.push_back(correlation(k));
  Index best = -1;
  for (Index i = 0; i < static_cast<Index>(c.size()); ++i)
    if (std::isfinite(c[static_cast<std::size_t>(i)]) &&
        (best < 0 || std::abs(c[static_cast<std::size_t>(i)]) > std::abs(c[static_cast<std::size_t>(best)])))
      best = i;
  if (best < 0) return out;
  const double c0 = c[static_cast<std::size_t>(best)];
  double offset = 0, value = c0;
  if (best > 0 && best + 1 < static_cast<Index>(c.size())) {
    const double sign = c0 < 0 ? -1 : 1;
    const double a = sign * c[static_cast<std::size_t>(best - 1)], b = sign * c0,
                 d = sign * c[static_cast<std::size_t>(best + 1)];
    const double curvature = a - 2 * b + d;
    if (curvature < 0) {
      offset = std::clamp(0.5 * (a - d) / curvature, -0.5, 0.5);
      value = sign * (b - 0.25 * (a - d) * offset);
    }
  }
  out.lag = (static_cast<double>(best - range.k) + offset) * interval;
  out.correlation = std::clamp(value, -1.0, 1.0);
  return out;
}

double effective_sample_size(const std::vector<Eigen::VectorXd>& pieces) {
  Index total = 0, longest = 0;
  double sum = 0;
  for (const auto& p : pieces) total += p.size(), longest = std::max(longest, p.size()), sum += p.sum();
  if (total == 0) return 0;
  const double mean = sum / static_cast<double>(total);
  // Lagged products within each piece by FFT (zero-padded to >= 2n: no wrap-around), summed.
  Eigen::VectorXd acc = Eigen::VectorXd::Zero(longest);
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> buffer, lagged;
  std::vector<std::complex<double>> spectrum;
  for (const auto& p : pieces) {
    const Index n = p.size();
    if (n == 0) continue;
    const auto nfft = static_cast<std::size_t>(pow2_at_least(2.0 * static_cast<double>(n)));
    buffer.assign(nfft, 0.0);
    for (Index i = 0; i < n; ++i) buffer[static_cast<std::size_t>(i)] = p(i) - mean;
    fft.fwd(spectrum, buffer);
    for (auto& z : spectrum) z = std::norm(z);
    fft.inv(lagged, spectrum, static_cast<Index>(nfft));
    for (Index k = 0; k < n; ++k) acc(k) += lagged[static_cast<std::size_t>(k)];
  }
  if (!(acc(0) > 0)) return static_cast<double>(total);
  double tail = 0;
  for (Index k = 1; k < longest; ++k) {
    const double rho = acc(k) / acc(0);
    if (!(rho > 0)) break;
    tail += rho;
  }
  return static_cast<double>(total) / (1 + 2 * tail);
}

std::vector<ResidualSeries> residual_series(const std::string& name, const preprocess::Samples& samples,
                                            const Eigen::MatrixXd& tau_model) {
  const Index n = samples.time.size();
  if (tau_model.rows() != n || tau_model.cols() != samples.tau.cols())
    throw std::invalid_argument(fmt::format("residual_series '{}': tau_model is {} x {}, the samples' tau {} x {}",
                                            name, tau_model.rows(), tau_model.cols(), n, samples.tau.cols()));
  if (!samples.piece.empty() && static_cast<Index>(samples.piece.size()) != n)
    throw std::invalid_argument(
        fmt::format("residual_series '{}': piece has {} entries for {} samples", name, samples.piece.size(), n));
  std::vector<ResidualSeries> out;
  Index begin = 0;
  for (Index i = 1; i <= n; ++i) {
    const bool split = i == n || (!samples.piece.empty() && samples.piece[static_cast<std::size_t>(i)] !=
                                                                samples.piece[static_cast<std::size_t>(i - 1)]);
    if (!split) continue;
    const Index len = i - begin;
    ResidualSeries s;
    s.name = name;
    s.interval = samples.interval;
    s.time = samples.time.segment(begin, len);
    s.q = samples.q.middleRows(begin, len);
    s.qd = samples.qd.middleRows(begin, len);
    s.qdd = samples.qdd.middleRows(begin, len);
    s.tau_measured = samples.tau.middleRows(begin, len);
    s.tau_model = tau_model.middleRows(begin, len);
    out.push_back(std::move(s));
    begin = i;
  }
  return out;
}

// --- The stage ------------------------------------------------------------------------------

Localization localize(const std::vector<ResidualSeries>& series, const std::vector<std::string>& joint_names,
                      const LocalizeOptions& options) {
  check_options(options);
  Index joints = 0;
  double interval = 0;
  const auto used = checked_series(series, joints, interval);
  if (!joint_names.empty() && static_cast<Index>(joint_names.size()) != joints)
    throw std::invalid_argument(fmt::format("localize: {} joint names for {} joints", joint_names.size(), joints));

  Localization loc;
  loc.interval = interval;
  loc.series = static_cast<int>(used.size());
  Index total = 0, longest = 0;
  for (const auto* s : used) total += s->time.size(), longest = std::max(longest, s->time.size());
  loc.samples = static_cast<int>(total);

  // Spectra: one segment length for all series (a shorter one when no series is long enough).
  long long length = welch_segment_length(interval, options.segment_seconds);
  if (length > longest) length = pow2_at_most(longest);
  const double nyquist = 0.5 / interval;
  if (length >= 4) {
    std::vector<Eigen::MatrixXd> residual, measured;
    for (const auto* s : used) {
      residual.emplace_back(s->tau_measured - s->tau_model);
      measured.push_back(s->tau_measured);
    }
    const Psd r = welch(residual, interval, static_cast<int>(length));
    const Psd m = welch(measured, interval, static_cast<int>(length));
    loc.spectrum.frequency = r.frequency;
    loc.spectrum.residual = r.power;
    loc.spectrum.measured = m.power;
    loc.spectrum.segments = r.segments;
    loc.spectrum.segment_length = r.segment_length;
  }
  const auto& edges = options.band_edges;
  for (std::size_t b = 0; b < edges.size(); ++b)
    loc.bands.push_back(b + 1 < edges.size() ? fmt::format("[{}, {}) Hz", edge_text(edges[b]), edge_text(edges[b + 1]))
                                             : fmt::format("[{}, {}] Hz", edge_text(edges[b]), edge_text(nyquist)));

  const double v0 = options.direction_velocity;
  for (Index j = 0; j < joints; ++j) {
    JointLocalization jl;
    jl.joint = static_cast<int>(j);
    jl.name = joint_names.empty() ? fmt::format("joint {}", j + 1) : joint_names[static_cast<std::size_t>(j)];
    const Pooled p = pool(used, j, total);
    const double sse = p.r.squaredNorm();
    jl.residual_rms = std::sqrt(sse / static_cast<double>(total));
    jl.torque_rms = std::sqrt(p.tau.squaredNorm() / static_cast<double>(total));

    // Regimes.
    std::vector<char> mask;
    mask.reserve(static_cast<std::size_t>(total));
    for (std::size_t s = 0; s < used.size(); ++s) {
      const auto m = reversal_mask(p.piece(p.t, s), p.piece(p.qd, s), options.reversal_window, v0);
      mask.insert(mask.end(), m.begin(), m.end());
    }
    jl.regimes.push_back(regime_stat("velocity reversal", p.r, mask, sse, jl.residual_rms));

    const Eigen::VectorXd abs_qdd = p.qdd.cwiseAbs();
    const double threshold =
        quantile(std::vector<double>(abs_qdd.data(), abs_qdd.data() + total), options.high_acceleration_quantile);
    for (Index i = 0; i < total; ++i) mask[static_cast<std::size_t>(i)] = abs_qdd(i) > threshold;
    jl.regimes.push_back(regime_stat(fmt::format("high acceleration (|qdd| > {} rad/s^2)", sig3(threshold)), p.r, mask,
                                     sse, jl.residual_rms));

    const std::vector<double> q_values(p.q.data(), p.q.data() + total);
    const int bands = options.position_bands;
    std::vector<double> q_edges;
    for (int b = 0; b <= bands; ++b) q_edges.push_back(quantile(q_values, static_cast<double>(b) / bands));
    for (int b = 0; b < bands; ++b) {
      const bool last = b + 1 == bands;
      const double lo = q_edges[static_cast<std::size_t>(b)], hi = q_edges[static_cast<std::size_t>(b) + 1];
      for (Index i = 0; i < total; ++i)
        mask[static_cast<std::size_t>(i)] = p.q(i) >= lo && (p.q(i) < hi || (last && p.q(i) <= hi));
      const char close = last ? ']' : ')';
      jl.regimes.push_back(regime_stat(fmt::format("q in [{:.3f}, {:.3f}{} rad ([{:.1f}, {:.1f}{} deg)", lo, hi, close,
                                                   lo * deg_per_rad, hi * deg_per_rad, close),
                                       p.r, mask, sse, jl.residual_rms));
    }

    std::vector<char> plus(static_cast<std::size_t>(total)), minus(static_cast<std::size_t>(total));
    for (Index i = 0; i < total; ++i) {
      plus[static_cast<std::size_t>(i)] = p.qd(i) > v0;
      minus[static_cast<std::size_t>(i)] = p.qd(i) < -v0;
    }
    jl.regimes.push_back(regime_stat(fmt::format("qd > +{} rad/s", v0), p.r, plus, sse, jl.residual_rms));
    jl.regimes.push_back(regime_stat(fmt::format("qd < -{} rad/s", v0), p.r, minus, sse, jl.residual_rms));

    // Direction step, its standard error with the autocorrelation of r about its group means.
    const RegimeStat& up = jl.regimes[jl.regimes.size() - 2];
    const RegimeStat& down = jl.regimes.back();
    jl.direction_step = jl.direction_step_se = nan;
    if (up.samples >= 2 && down.samples >= 2) {
      // e = r about its direction group's mean; 0 on slow samples (neither group), so their
      // residual, which flips with the direction, adds no spurious correlation.
      Eigen::VectorXd e(total);
      double var_up = 0, var_down = 0;
      for (Index i = 0; i < total; ++i) {
        const auto k = static_cast<std::size_t>(i);
        e(i) = plus[k] ? p.r(i) - up.mean : minus[k] ? p.r(i) - down.mean : 0.0;
        if (plus[k]) var_up += e(i) * e(i);
        if (minus[k]) var_down += e(i) * e(i);
      }
      var_up /= up.samples - 1;
      var_down /= down.samples - 1;
      std::vector<Eigen::VectorXd> pieces;
      for (std::size_t s = 0; s < used.size(); ++s) pieces.push_back(p.piece(e, s));
      // 1 + 2 sum rho_k (N_eff = N / it); the zeros count in N and in N_eff alike.
      const double n_eff = effective_sample_size(pieces);
      const double inflation = n_eff > 0 ? static_cast<double>(total) / n_eff : 1;
      jl.direction_step = (up.mean - down.mean) / 2;
      jl.direction_step_se = 0.5 * std::sqrt(inflation * (var_up / up.samples + var_down / down.samples));
    }

    // Power per band, peak.
    const auto& f = loc.spectrum.frequency;
    jl.band_power_fraction = Eigen::VectorXd::Constant(static_cast<Index>(edges.size()), nan);
    jl.peak_frequency = nan;
    if (f.size() > 0) {
      const Eigen::VectorXd psd = loc.spectrum.residual.col(j);
      const double all = psd.sum();
      for (std::size_t b = 0; b < edges.size(); ++b) {
        double in = 0;
        for (Index k = 0; k < f.size(); ++k)
          if (f(k) >= edges[b] && (b + 1 == edges.size() || f(k) < edges[b + 1])) in += psd(k);
        jl.band_power_fraction(static_cast<Index>(b)) = all > 0 ? in / all : nan;
      }
      if (all > 0) {
        Index k = 0;
        psd.maxCoeff(&k);
        double offset = 0;
        if (k > 0 && k + 1 < psd.size() && psd(k - 1) > 0 && psd(k + 1) > 0) {
          const double a = std::log(psd(k - 1)), b = std::log(psd(k)), c = std::log(psd(k + 1));
          const double curvature = a - 2 * b + c;
          if (curvature < 0) offset = std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
        }
        jl.peak_frequency = (static_cast<double>(k) + offset) * (f.size() > 1 ? f(1) : 0);
      }
    }

    // Lags.
    std::vector<Eigen::VectorXd> measured, model, residual, velocity;
    for (std::size_t s = 0; s < used.size(); ++s) {
      measured.push_back(p.piece(p.tau, s));
      model.push_back(used[s]->tau_model.col(j));
      residual.push_back(p.piece(p.r, s));
      velocity.push_back(p.piece(p.qd, s));
    }
    jl.torque_lag = torque_lag(measured, model, interval, options.max_lag);
    std::vector<Eigen::MatrixXd> friction;
    for (const auto& v : velocity) {
      Eigen::MatrixXd x(v.size(), 3);
      for (Index i = 0; i < v.size(); ++i) x.row(i) << (v(i) > v0 ? 1.0 : v(i) < -v0 ? -1.0 : 0.0), v(i), 1.0;
      friction.push_back(std::move(x));
    }
    jl.torque_lag_adjusted = torque_lag(measured, model, interval, options.max_lag, friction);
    const auto peak = cross_correlation_peak(residual, velocity, interval, options.max_lag);
    jl.velocity_lag = peak.lag;
    jl.velocity_correlation = peak.correlation;

    jl.summary = joint_summary(jl, edges, options.max_lag);
    loc.joints.push_back(std::move(jl));
  }
  return loc;
}

}  // namespace symoro::diagnose
