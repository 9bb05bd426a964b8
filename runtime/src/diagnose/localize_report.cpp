#include "symoro/detail/numbers.hpp"
#include "symoro/diagnose/localize_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "symoro/report/markdown_table.hpp"
#include "symoro/report/svg_plot.hpp"
#include "symoro/io/atomic_file.hpp"

namespace symoro::diagnose {

namespace {

using Index = Eigen::Index;
using symoro::detail::nan;

// --- Text ---------------------------------------------------------------------------------

std::string fixed(double v, int decimals) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : "n/a"; }

// Three significant digits, fixed notation.
std::string sig3_text(double v) {
  if (!std::isfinite(v)) return "n/a";
  if (v == 0) return "0";
  return fixed(v, std::clamp(2 - static_cast<int>(std::floor(std::log10(std::abs(v)))), 0, 9));
}

std::string percent_text(double fraction) { return std::isfinite(fraction) ? fixed(100 * fraction, 0) + " %" : "n/a"; }

std::string heading(int level, const std::string& text) {
  return std::string(static_cast<std::size_t>(std::clamp(level, 1, 6)), '#') + " " + text + "\n\n";
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string caption(const std::string& link) {
  if (ends_with(link, "residual_velocity.svg")) return "Residual vs joint velocity (friction signature)";
  if (ends_with(link, "residual_spectrum.svg")) return "Residual and measured torque spectra";
  if (ends_with(link, "residual_time.svg")) return "Residual vs time";
  return "Localization figure";
}

// --- Figures ------------------------------------------------------------------------------

std::string file_name(const std::string& prefix, const std::string& base) {
  return prefix.empty() ? base : prefix + "_" + base;
}

svg::Style line_style(const char* colour, double width) {
  svg::Style s;
  s.colour = colour;
  s.width = width;
  return s;
}

// At most about `limit` points of (x, y) in order: per bucket of consecutive points its
// minimum and maximum y (in their order), so spikes survive the decimation. Runs between
// non-finite pairs (breaks) are decimated separately and stay separated by a NaN pair.
void decimate_line(const std::vector<double>& x, const std::vector<double>& y, std::size_t limit,
                   std::vector<double>& out_x, std::vector<double>& out_y) {
  const std::size_t n = x.size();
  if (n <= limit || limit < 4) {
    out_x = x, out_y = y;
    return;
  }
  const std::size_t bucket = (2 * n + limit - 1) / limit;
  auto finite = [&](std::size_t i) { return std::isfinite(x[i]) && std::isfinite(y[i]); };
  std::size_t i = 0;
  while (i < n) {
    if (!finite(i)) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < n && finite(end)) ++end;
    if (!out_x.empty()) out_x.push_back(nan), out_y.push_back(nan);
    for (std::size_t b = i; b < end; b += bucket) {
      const std::size_t e = std::min(end, b + bucket);
      std::size_t lo = b, hi = b;
      for (std::size_t k = b; k < e; ++k) {
        if (y[k] < y[lo]) lo = k;
        if (y[k] > y[hi]) hi = k;
      }
      const std::size_t first = std::min(lo, hi), second = std::max(lo, hi);
      out_x.push_back(x[first]), out_y.push_back(y[first]);
      if (second != first) out_x.push_back(x[second]), out_y.push_back(y[second]);
    }
    i = end;
  }
}

std::string velocity_figure(const std::vector<ResidualSeries>& series, const Localization& loc, int max_points) {
  svg::Figure f;
  f.title = "Residual vs joint velocity";
  const auto joints = loc.joints.size();
  f.columns = static_cast<int>(std::min<std::size_t>(4, std::max<std::size_t>(1, joints)));
  for (std::size_t j = 0; j < joints; ++j) {
    const auto col = static_cast<Index>(loc.joints[j].joint);
    std::vector<double> v, r;
    for (const auto& s : series) {
      if (s.time.size() == 0 || col >= s.qd.cols()) continue;
      for (Index i = 0; i < s.time.size(); ++i) {
        v.push_back(s.qd(i, col));
        r.push_back(s.tau_measured(i, col) - s.tau_model(i, col));
      }
    }
    svg::Panel p;
    p.title = loc.joints[j].name;
    p.x_label = "qd [rad/s]";
    p.y_label = "r = τ_measured − τ_model [N m]";
    svg::Series points;
    points.name = "samples";
    points.style.colour = "#1f77b4";
    points.style.size = 1.6;
    points.style.opacity = 0.35;
    const std::size_t stride = max_points > 0 ? (v.size() + max_points - 1) / static_cast<std::size_t>(max_points) : 1;
    for (std::size_t i = 0; i < v.size(); i += std::max<std::size_t>(1, stride)) {
      points.x.push_back(v[i]);
      points.y.push_back(r[i]);
    }
    p.points.push_back(points);

    // The binned mean over the central 99 % of velocities: the friction curve the model misses.
    if (v.size() >= 20) {
      std::vector<double> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      const double lo = sorted[sorted.size() / 200], hi = sorted[sorted.size() - 1 - sorted.size() / 200];
      constexpr int bins = 40;
      if (hi > lo) {
        std::vector<double> sum(bins, 0.0);
        std::vector<int> count(bins, 0);
        for (std::size_t i = 0; i < v.size(); ++i) {
          if (v[i] < lo || v[i] > hi) continue;
          const int b = std::min(bins - 1, static_cast<int>((v[i] - lo) / (hi - lo) * bins));
          sum[static_cast<std::size_t>(b)] += r[i];
          ++count[static_cast<std::size_t>(b)];
        }
        svg::Series mean;
        mean.name = "binned mean";
        mean.style = line_style("#d62728", 1.8);
        for (int b = 0; b < bins; ++b) {
          mean.x.push_back(lo + (b + 0.5) * (hi - lo) / bins);
          mean.y.push_back(count[static_cast<std::size_t>(b)] >= 5
                               ? sum[static_cast<std::size_t>(b)] / count[static_cast<std::size_t>(b)]
                               : nan);
        }
        p.lines.push_back(mean);
      }
    }
    f.panels.push_back(p);
  }
  return svg::render(f);
}

std::string spectrum_figure(const Localization& loc) {
  const Spectrum& s = loc.spectrum;
  svg::Figure f;
  f.title = fmt::format("Power spectral density (Welch, {} segments of {:.2f} s)", s.segments,
                        s.segment_length * loc.interval);
  f.columns = static_cast<int>(std::min<std::size_t>(4, std::max<std::size_t>(1, loc.joints.size())));
  for (const auto& jl : loc.joints) {
    const auto j = static_cast<Index>(jl.joint);
    svg::Panel p;
    p.title = jl.name;
    p.x_label = "f [Hz]";
    p.y_label = "log10 PSD [(N m)²/Hz]";
    svg::Series residual, measured;
    residual.name = "residual";
    residual.style = line_style("#d62728", 1.5);
    measured.name = "measured torque";
    measured.style = line_style("#555555", 1.1);
    measured.style.dash = "5 3";
    double top = -std::numeric_limits<double>::infinity(), bottom = std::numeric_limits<double>::infinity();
    for (Index k = 0; k < s.frequency.size(); ++k) {
      const double a = std::log10(s.residual(k, j)), b = std::log10(s.measured(k, j));
      residual.x.push_back(s.frequency(k)), residual.y.push_back(a);
      measured.x.push_back(s.frequency(k)), measured.y.push_back(b);
      for (double v : {a, b})
        if (std::isfinite(v)) top = std::max(top, v), bottom = std::min(bottom, v);
    }
    // Nine decades at most: below the pre-filter's cutoff the PSD can drop to rounding noise,
    // which would squash the part that matters.
    if (std::isfinite(top)) p.y_range = svg::Range{std::max(bottom, top - 9), top};
    if (s.frequency.size() > 0) p.x_range = svg::Range{0, s.frequency(s.frequency.size() - 1)};
    p.lines = {measured, residual};
    f.panels.push_back(p);
  }
  return svg::render(f);
}

std::string time_figure(const std::vector<ResidualSeries>& series, const Localization& loc, const std::string& name,
                        int max_line_points) {
  svg::Figure f;
  f.title = name + ": residual τ_measured − τ_model";
  f.columns = 1;
  f.panel_width = 760;
  f.panel_height = 170;
  for (const auto& jl : loc.joints) {
    const auto j = static_cast<Index>(jl.joint);
    std::vector<double> t, r;
    for (const auto& s : series) {
      if (s.name != name || s.time.size() == 0 || j >= s.qd.cols()) continue;
      if (!t.empty()) t.push_back(nan), r.push_back(nan);  // a gap between pieces
      for (Index i = 0; i < s.time.size(); ++i) {
        t.push_back(s.time(i));
        r.push_back(s.tau_measured(i, j) - s.tau_model(i, j));
      }
    }
    svg::Panel p;
    p.title = jl.name;
    p.x_label = "t [s]";
    p.y_label = "r [N m]";
    svg::Series line;
    line.style = line_style("#d62728", 1.0);
    decimate_line(t, r, static_cast<std::size_t>(std::max(0, max_line_points)), line.x, line.y);
    p.lines.push_back(line);
    f.panels.push_back(p);
  }
  return svg::render(f);
}

}  // namespace

std::string localization_markdown(const Localization& loc, const std::vector<std::string>& figures,
                                  const std::string& title, int heading_level) {
  std::string md = heading(heading_level, title);
  md += fmt::format(
      "Residual r = τ_measured − τ_model, {} samples per joint in {} series at {} ms. Reversals: within "
      "the window around a sign change of qd, or slow. Direction step: (mean r moving + − mean r moving −) / 2 "
      "± its standard error (autocorrelation counted). Torque lag: the shift that best aligns the measured "
      "torque with the model's (+: the measurement lags); a friction misfit biases it, so it is also given with "
      "an offset, a Coulomb step and a viscous term of the residual fitted at every shift. corr(r, qd): the peak "
      "normalized cross-correlation "
      "and its lag (+: r lags qd).\n\n",
      loc.samples, loc.series, fixed(loc.interval * 1000, 1));

  markdown::Table main({"joint", "residual rms [N m]", "of torque rms", "SSE at reversals", "samples at reversals",
                        "direction step [N m]", "torque lag [ms]", "lag, friction removed [ms]", "peak [Hz]",
                        "dominant band", "corr(r, qd)", "r lag [ms]"},
                       markdown::Align::first_left);
  for (const auto& jl : loc.joints) {
    const RegimeStat* rev = jl.regimes.empty() ? nullptr : &jl.regimes.front();
    std::string band = "n/a";
    if (jl.band_power_fraction.size() > 0 && jl.band_power_fraction.allFinite()) {
      Index b = 0;
      jl.band_power_fraction.maxCoeff(&b);
      if (static_cast<std::size_t>(b) < loc.bands.size())
        band = loc.bands[static_cast<std::size_t>(b)] + " (" + percent_text(jl.band_power_fraction(b)) + ")";
    }
    main.row({jl.name, sig3_text(jl.residual_rms),
              percent_text(jl.torque_rms > 0 ? jl.residual_rms / jl.torque_rms : nan),
              rev ? percent_text(rev->sse_share) : "n/a", rev ? percent_text(rev->fraction) : "n/a",
              std::isfinite(jl.direction_step) ? sig3_text(jl.direction_step) + " ± " + sig3_text(jl.direction_step_se)
                                               : "n/a",
              fixed(jl.torque_lag * 1000, 2), fixed(jl.torque_lag_adjusted * 1000, 2), sig3_text(jl.peak_frequency),
              band, fixed(jl.velocity_correlation, 2), fixed(jl.velocity_lag * 1000, 1)});
  }
  md += main.str() + "\n";
  for (const auto& jl : loc.joints) md += "- " + jl.summary + "\n";
  md += "\n";
  for (const auto& link : figures) md += fmt::format("![{}]({})\n\n", caption(link), link);

  md += heading(heading_level + 1, "Residual by motion regime");
  markdown::Table regimes({"joint", "regime", "samples", "mean [N m]", "rms [N m]", "rms / overall", "SSE share"},
                          markdown::Align::first_left);
  for (const auto& jl : loc.joints)
    for (const auto& r : jl.regimes)
      regimes.row({jl.name, r.regime, fmt::format("{} ({})", r.samples, percent_text(r.fraction)), sig3_text(r.mean),
                   sig3_text(r.rms), fixed(r.rms_ratio, 2), percent_text(r.sse_share)});
  md += regimes.str() + "\n";

  md += heading(heading_level + 1, "Residual power by frequency band");
  if (loc.spectrum.frequency.size() == 0) {
    md += "No spectrum: every series is shorter than 4 samples.\n\n";
    return md;
  }
  md += fmt::format("Welch: {} Hann segments of {} samples ({:.2f} s, {:.3f} Hz resolution), 50 % overlap.\n\n",
                    loc.spectrum.segments, loc.spectrum.segment_length, loc.spectrum.segment_length * loc.interval,
                    1 / (loc.spectrum.segment_length * loc.interval));
  std::vector<std::string> header{"joint"};
  header.insert(header.end(), loc.bands.begin(), loc.bands.end());
  header.push_back("peak [Hz]");
  markdown::Table bands(header, markdown::Align::first_left);
  for (const auto& jl : loc.joints) {
    std::vector<std::string> cells{jl.name};
    for (Index b = 0; b < jl.band_power_fraction.size(); ++b) cells.push_back(percent_text(jl.band_power_fraction(b)));
    cells.resize(loc.bands.size() + 1, "n/a");
    cells.push_back(sig3_text(jl.peak_frequency));
    bands.row(cells);
  }
  md += bands.str() + "\n";
  return md;
}

std::vector<std::string> write_localization_figures(const std::vector<ResidualSeries>& series, const Localization& loc,
                                                    const std::filesystem::path& dir, const std::string& prefix,
                                                    const LocalizationFigureOptions& options) {
  std::filesystem::create_directories(dir);
  std::vector<std::string> written;
  auto put = [&](const std::string& base, const std::string& content) {
    const std::string name = file_name(prefix, base);
    io::write_file_atomically(dir / name, content);
    written.push_back(name);
  };
  if (loc.joints.empty()) return written;
  put("residual_velocity.svg", velocity_figure(series, loc, options.max_points));
  if (loc.spectrum.frequency.size() > 0) put("residual_spectrum.svg", spectrum_figure(loc));
  std::string name = options.time_trajectory;
  if (name.empty())
    for (const auto& s : series)
      if (s.time.size() > 0) {
        name = s.name;
        break;
      }
  const bool found = std::any_of(series.begin(), series.end(),
                                 [&](const ResidualSeries& s) { return s.name == name && s.time.size() > 0; });
  if (found) put("residual_time.svg", time_figure(series, loc, name, options.max_line_points));
  return written;
}

}  // namespace symoro::diagnose
