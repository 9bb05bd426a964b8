#include "symoro/report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include <fmt/format.h>

namespace symoro::svg {

namespace {

// Panel margins around the plot area (px): room for tick labels, axis labels and the title.
constexpr double margin_left = 66, margin_right = 16, margin_top = 28, margin_bottom = 46;
constexpr double title_height = 30, legend_row = 18, figure_pad = 10;

// Integer power of ten, exact for the exponents axes use.
double pow10(int e) {
  double p = 1;
  for (int i = 0; i < std::abs(e); ++i) p *= 10;
  return e < 0 ? 1 / p : p;
}

// k * m * 10^e computed so that, e.g., 3 * 0.1 gives 0.3 (one correctly rounded division)
// instead of 0.30000000000000004.
double scaled(long long k, int m, int e) {
  const double km = static_cast<double>(k) * m;
  return e < 0 ? km / pow10(-e) : km * pow10(e);
}

struct Axis {
  double lo = 0, hi = 1;
  Ticks ticks;
};

struct Extent {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return lo > hi; }
  // Widened by `fraction` of its width on both sides, so markers do not sit on the frame.
  Extent padded(double fraction) const {
    if (empty()) return *this;
    const double pad = (hi - lo) * fraction;
    return {lo - pad, hi + pad};
  }
  void merge(const Extent& other) {
    if (other.empty()) return;
    add(other.lo);
    add(other.hi);
  }
};

// The axis over `data`, or over `cover` when given, widened to its ticks.
Axis make_axis(const std::optional<Range>& cover, const Extent& data, int intervals) {
  Axis a;
  if (cover)
    a.ticks = nice_ticks(std::min(cover->lo, cover->hi), std::max(cover->lo, cover->hi), intervals);
  else
    a.ticks = data.empty() ? nice_ticks(0, 1, intervals) : nice_ticks(data.lo, data.hi, intervals);
  a.lo = a.ticks.values.front();
  a.hi = a.ticks.values.back();
  return a;
}

std::string num(double v) { return fmt::format("{:.2f}", v); }

void append_marker(std::string& out, const Style& s, double cx, double cy, const char* cls) {
  const double r = s.size;
  const std::string paint = fmt::format(R"(fill="{}" fill-opacity="{}" stroke="{}" stroke-width="0.6")",
                                        xml_escape(s.colour), s.opacity, xml_escape(s.colour));
  auto path = [&](const std::string& d) {
    fmt::format_to(std::back_inserter(out),
                   R"(<path class="{}" d="{}" {}/>)"
                   "\n",
                   cls, d, paint);
  };
  switch (s.marker) {
    case Marker::circle:
      fmt::format_to(std::back_inserter(out),
                     R"(<circle class="{}" cx="{}" cy="{}" r="{}" {}/>)"
                     "\n",
                     cls, num(cx), num(cy), num(r), paint);
      break;
    case Marker::square: {
      const double h = 0.9 * r;
      fmt::format_to(std::back_inserter(out),
                     R"(<rect class="{}" x="{}" y="{}" width="{}" height="{}" {}/>)"
                     "\n",
                     cls, num(cx - h), num(cy - h), num(2 * h), num(2 * h), paint);
      break;
    }
    case Marker::triangle:
      path(fmt::format("M{} {}L{} {}L{} {}Z", num(cx), num(cy - 1.25 * r), num(cx + 1.1 * r), num(cy + 0.7 * r),
                       num(cx - 1.1 * r), num(cy + 0.7 * r)));
      break;
    case Marker::diamond:
      path(fmt::format("M{} {}L{} {}L{} {}L{} {}Z", num(cx), num(cy - 1.3 * r), num(cx + 1.3 * r), num(cy), num(cx),
                       num(cy + 1.3 * r), num(cx - 1.3 * r), num(cy)));
      break;
    case Marker::cross:
      fmt::format_to(std::back_inserter(out),
                     R"(<path class="{}" d="M{} {}L{} {}M{} {}L{} {}" fill="none" stroke="{}" stroke-width="1.6"/>)"
                     "\n",
                     cls, num(cx - r), num(cy - r), num(cx + r), num(cy + r), num(cx - r), num(cy + r), num(cx + r),
                     num(cy - r), xml_escape(s.colour));
      break;
  }
}

std::string line_paint(const Style& s) {
  std::string paint = fmt::format(R"(fill="none" stroke="{}" stroke-width="{}" stroke-linejoin="round")",
                                  xml_escape(s.colour), s.width);
  if (!s.dash.empty()) paint += fmt::format(R"( stroke-dasharray="{}")", xml_escape(s.dash));
  return paint;
}

enum class Kind { point, line, bar };

struct LegendEntry {
  std::string name;
  Style style;
  Kind kind;
};

std::vector<LegendEntry> legend_entries(const Figure& f) {
  std::vector<LegendEntry> entries;
  auto add = [&](const std::vector<Series>& all, Kind kind) {
    for (const auto& s : all) {
      if (s.name.empty()) continue;
      const bool seen = std::any_of(entries.begin(), entries.end(),
                                    [&](const LegendEntry& e) { return e.name == s.name && e.kind == kind; });
      if (!seen) entries.push_back({s.name, s.style, kind});
    }
  };
  for (const auto& p : f.panels) {
    add(p.points, Kind::point);
    add(p.lines, Kind::line);
    add(p.bars, Kind::bar);
  }
  return entries;
}

// A rough text width (px at font-size 11) for laying out legend entries.
double text_width(const std::string& text) { return 6.2 * static_cast<double>(text.size()); }

struct LegendLayout {
  std::vector<std::pair<double, double>> at;  // entry origins relative to the legend's top left
  double height = 0;
};

LegendLayout layout_legend(const std::vector<LegendEntry>& entries, double width) {
  LegendLayout l;
  double x = 0, y = 0;
  for (const auto& e : entries) {
    const double w = 34 + text_width(e.name) + 14;
    if (x > 0 && x + w > width) {
      x = 0;
      y += legend_row;
    }
    l.at.emplace_back(x, y);
    x += w;
  }
  l.height = entries.empty() ? 0 : y + legend_row;
  return l;
}

void append_legend(std::string& out, const std::vector<LegendEntry>& entries, const LegendLayout& layout, double left,
                   double top) {
  out += "<g class=\"legend\">\n";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& e = entries[i];
    const double x = left + layout.at[i].first, y = top + layout.at[i].second + legend_row / 2;
    switch (e.kind) {
      case Kind::point:
        append_marker(out, e.style, x + 12, y, "legend-marker");
        break;
      case Kind::line:
        fmt::format_to(std::back_inserter(out),
                       R"(<line x1="{}" y1="{}" x2="{}" y2="{}" {}/>)"
                       "\n",
                       num(x), num(y), num(x + 26), num(y), line_paint(e.style));
        break;
      case Kind::bar:
        fmt::format_to(std::back_inserter(out),
                       R"(<rect x="{}" y="{}" width="16" height="10" fill="{}" fill-opacity="{}"/>)"
                       "\n",
                       num(x + 4), num(y - 5), xml_escape(e.style.colour), e.style.opacity);
        break;
    }
    fmt::format_to(std::back_inserter(out),
                   R"(<text x="{}" y="{}" dominant-baseline="middle">{}</text>)"
                   "\n",
                   num(x + 32), num(y), xml_escape(e.name));
  }
  out += "</g>\n";
}

// A panel's plot area in the figure and its axes: where a data point is drawn.
struct PanelFrame {
  double left, top;     // the panel's corner in the figure
  double x0, y0, w, h;  // the plot area
  Axis xa, ya;
  double sx(double x) const { return x0 + (x - xa.lo) / (xa.hi - xa.lo) * w; }
  double sy(double y) const { return y0 + h - (y - ya.lo) / (ya.hi - ya.lo) * h; }
};

// The data's extents: points and labels padded on both axes, lines only vertically (a time axis
// should start and end at the data), bars always from zero.
std::pair<Extent, Extent> data_extents(const Panel& p) {
  Extent xe, ye, px, py;
  for (const auto& s : p.points)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) px.add(s.x[i]), py.add(s.y[i]);
  for (const auto& l : p.labels)
    if (std::isfinite(l.x) && std::isfinite(l.y)) px.add(l.x), py.add(l.y);
  xe.merge(px.padded(0.04));
  ye.merge(py.padded(0.04));
  Extent ly;
  for (const auto& s : p.lines)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) xe.add(s.x[i]), ly.add(s.y[i]);
  ye.merge(ly.padded(0.04));
  if (!p.bars.empty()) {
    Extent be;
    be.add(0);
    for (const auto& s : p.bars)
      for (double v : s.y) be.add(v);
    // Headroom above the tallest bar (and below the lowest), but the base stays at zero.
    const Extent padded = be.padded(0.05);
    ye.add(be.lo < 0 ? padded.lo : 0);
    ye.add(be.hi > 0 ? padded.hi : 0);
  }
  return {xe, ye};
}

PanelFrame panel_frame(const Panel& p, double left, double top, double width, double height) {
  PanelFrame f;
  f.left = left, f.top = top;
  f.x0 = left + margin_left, f.y0 = top + margin_top;
  f.w = std::max(20.0, width - margin_left - margin_right);
  f.h = std::max(20.0, height - margin_top - margin_bottom);
  const auto [xe, ye] = data_extents(p);
  const int x_intervals = std::max(2, static_cast<int>(f.w / 75));
  const int y_intervals = std::max(2, static_cast<int>(f.h / 45));
  if (!p.bars.empty()) {
    f.xa.lo = -0.5;
    f.xa.hi = std::max<double>(1, static_cast<double>(p.categories.size())) - 0.5;
  } else {
    f.xa = make_axis(p.x_range, xe, x_intervals);
  }
  f.ya = make_axis(p.y_range, ye, y_intervals);
  return f;
}

// The title, grid, tick labels and axis labels.
void append_frame(std::string& out, const Panel& p, const PanelFrame& f) {
  const double x0 = f.x0, y0 = f.y0, w = f.w, h = f.h, left = f.left, top = f.top;
  const Axis &xa = f.xa, &ya = f.ya;
  const bool bars = !p.bars.empty();
  const auto sx = [&f](double x) { return f.sx(x); };
  const auto sy = [&f](double y) { return f.sy(y); };
  auto out_it = std::back_inserter(out);
  if (!p.title.empty())
    fmt::format_to(out_it,
                   R"(<text class="panel-title" x="{}" y="{}" text-anchor="middle" font-weight="bold">{}</text>)"
                   "\n",
                   num(x0 + w / 2), num(top + 18), xml_escape(p.title));

  // Grid and tick labels.
  fmt::format_to(out_it, "<g stroke=\"#e3e3e3\" stroke-width=\"1\">\n");
  for (double t : ya.ticks.values)
    fmt::format_to(out_it,
                   R"(<line x1="{}" y1="{}" x2="{}" y2="{}"/>)"
                   "\n",
                   num(x0), num(sy(t)), num(x0 + w), num(sy(t)));
  if (!bars)
    for (double t : xa.ticks.values)
      fmt::format_to(out_it,
                     R"(<line x1="{}" y1="{}" x2="{}" y2="{}"/>)"
                     "\n",
                     num(sx(t)), num(y0), num(sx(t)), num(y0 + h));
  out += "</g>\n";
  for (double t : ya.ticks.values)
    fmt::format_to(out_it,
                   R"(<text class="ytick" x="{}" y="{}" text-anchor="end" dominant-baseline="middle">{}</text>)"
                   "\n",
                   num(x0 - 5), num(sy(t)), tick_text(t, ya.ticks.decimals));
  if (bars) {
    for (std::size_t c = 0; c < p.categories.size(); ++c)
      fmt::format_to(out_it,
                     R"(<text class="category" x="{}" y="{}" text-anchor="middle">{}</text>)"
                     "\n",
                     num(sx(static_cast<double>(c))), num(y0 + h + 15), xml_escape(p.categories[c]));
  } else {
    for (double t : xa.ticks.values)
      fmt::format_to(out_it,
                     R"(<text class="xtick" x="{}" y="{}" text-anchor="middle">{}</text>)"
                     "\n",
                     num(sx(t)), num(y0 + h + 15), tick_text(t, xa.ticks.decimals));
  }
  if (!p.x_label.empty())
    fmt::format_to(out_it,
                   R"(<text class="x-label" x="{}" y="{}" text-anchor="middle">{}</text>)"
                   "\n",
                   num(x0 + w / 2), num(y0 + h + 34), xml_escape(p.x_label));
  if (!p.y_label.empty()) {
    const double lx = left + 14, ly_ = y0 + h / 2;
    fmt::format_to(
        out_it,
        R"~(<text class="y-label" x="{}" y="{}" text-anchor="middle" transform="rotate(-90 {} {})">{}</text>)~"
        "\n",
        num(lx), num(ly_), num(lx), num(ly_), xml_escape(p.y_label));
  }
}

// The bars, lines, markers and rings, clipped to the plot area.
void append_data(std::string& out, const Panel& p, const PanelFrame& f, int index) {
  const auto sx = [&f](double x) { return f.sx(x); };
  const auto sy = [&f](double y) { return f.sy(y); };
  const bool bars = !p.bars.empty();
  auto out_it = std::back_inserter(out);
  // Data, clipped to the plot area.
  fmt::format_to(out_it, "<g clip-path=\"url(#clip{})\">\n", index);
  if (bars) {
    const double group = 0.8, bar = group / static_cast<double>(p.bars.size());
    for (std::size_t s = 0; s < p.bars.size(); ++s) {
      const auto& series = p.bars[s];
      for (std::size_t c = 0; c < std::min(series.y.size(), p.categories.size()); ++c) {
        const double v = series.y[c];
        if (!std::isfinite(v)) continue;
        const double xl = static_cast<double>(c) - group / 2 + bar * static_cast<double>(s);
        const double top_y = std::min(sy(v), sy(0)), bottom_y = std::max(sy(v), sy(0));
        fmt::format_to(
            out_it,
            R"(<rect class="bar" x="{}" y="{}" width="{}" height="{}" fill="{}" fill-opacity="{}"><title>{}: {}</title></rect>)"
            "\n",
            num(sx(xl)), num(top_y), num(sx(xl + bar) - sx(xl)), num(bottom_y - top_y), xml_escape(series.style.colour),
            series.style.opacity, xml_escape(series.name), v);
      }
    }
  }
  for (const auto& s : p.lines) {
    std::string points;
    int count = 0;
    auto flush = [&] {
      if (count >= 2)
        fmt::format_to(out_it,
                       R"(<polyline class="line" {} points="{}"/>)"
                       "\n",
                       line_paint(s.style), points);
      points.clear();
      count = 0;
    };
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        flush();
        continue;
      }
      if (count++ > 0) points += ' ';
      points += num(sx(s.x[i])) + "," + num(sy(s.y[i]));
    }
    flush();
  }
  for (const auto& s : p.points)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) append_marker(out, s.style, sx(s.x[i]), sy(s.y[i]), "marker");
  for (const auto& l : p.labels)
    if (l.ring && std::isfinite(l.x) && std::isfinite(l.y))
      fmt::format_to(out_it,
                     R"(<circle class="ring" cx="{}" cy="{}" r="8" fill="none" stroke="{}" stroke-width="1.8"/>)"
                     "\n",
                     num(sx(l.x)), num(sy(l.y)), xml_escape(l.colour));
  out += "</g>\n";
}

// Labels beside their points, turned to the left near the right edge to stay readable.
void append_point_labels(std::string& out, const Panel& p, const PanelFrame& f) {
  auto out_it = std::back_inserter(out);
  for (const auto& l : p.labels) {
    if (!std::isfinite(l.x) || !std::isfinite(l.y) || l.text.empty()) continue;
    const double px_ = f.sx(l.x), py_ = f.sy(l.y);
    const bool left_side = px_ > f.x0 + 0.7 * f.w;
    fmt::format_to(out_it,
                   R"(<text class="point-label" x="{}" y="{}" text-anchor="{}" fill="{}">{}</text>)"
                   "\n",
                   num(left_side ? px_ - 9 : px_ + 9), num(py_ - 7), left_side ? "end" : "start", xml_escape(l.colour),
                   xml_escape(l.text));
  }
}

void append_panel(std::string& out, const Panel& p, int index, double left, double top, double width, double height) {
  const PanelFrame f = panel_frame(p, left, top, width, height);
  auto out_it = std::back_inserter(out);
  fmt::format_to(out_it, "<g class=\"panel\">\n");
  fmt::format_to(out_it,
                 R"(<clipPath id="clip{}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath>)"
                 "\n",
                 index, num(f.x0), num(f.y0), num(f.w), num(f.h));
  append_frame(out, p, f);
  append_data(out, p, f, index);
  append_point_labels(out, p, f);
  fmt::format_to(out_it,
                 R"(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#444" stroke-width="1"/>)"
                 "\n",
                 num(f.x0), num(f.y0), num(f.w), num(f.h));
  out += "</g>\n";
}

}  // namespace

Ticks nice_ticks(double lo, double hi, int intervals) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0, hi = 1;
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
    const double pad = lo != 0 ? 0.1 * std::abs(lo) : 1;
    lo -= pad;
    hi += pad;
  }
  intervals = std::max(1, intervals);
  const double raw = (hi - lo) / intervals;
  int e = static_cast<int>(std::floor(std::log10(raw)));
  const double f = raw / pow10(e);
  int m = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
  if (m == 10) m = 1, ++e;
  Ticks t;
  t.step = scaled(1, m, e);
  t.decimals = std::max(0, -e);
  // Indices of the first and last multiples, forgiving the rounding in lo / step (0.3 / 0.1
  // is 2.9999999999999996 and must count as 3).
  auto index = [&](double v, bool down) {
    const double q = v / t.step, r = std::round(q);
    if (std::abs(q - r) < 1e-9 * std::max(1.0, std::abs(q))) return static_cast<long long>(r);
    return static_cast<long long>(down ? std::floor(q) : std::ceil(q));
  };
  const long long first = index(lo, true), last = index(hi, false);
  for (long long k = first; k <= last; ++k) t.values.push_back(scaled(k, m, e));
  return t;
}

std::string tick_text(double value, int decimals) {
  std::string s = fmt::format("{:.{}f}", value, std::max(0, decimals));
  if (s.find_first_not_of("-0.") == std::string::npos && s.front() == '-') s.erase(0, 1);
  return s;
}

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string render(const Figure& figure) {
  const int count = static_cast<int>(figure.panels.size());
  const int columns = figure.columns > 0 ? std::min(figure.columns, std::max(1, count)) : std::max(1, count);
  const int rows = std::max(1, (count + columns - 1) / columns);
  const double width = columns * figure.panel_width;
  const double title = figure.title.empty() ? 0 : title_height;
  const auto entries = figure.legend ? legend_entries(figure) : std::vector<LegendEntry>{};
  const LegendLayout legend = layout_legend(entries, width - 2 * figure_pad);
  const double legend_height = entries.empty() ? 0 : legend.height + figure_pad;
  const double height = title + rows * figure.panel_height + legend_height;

  std::string out;
  fmt::format_to(
      std::back_inserter(out),
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{1}" viewBox="0 0 {0} {1}" font-family="Helvetica, Arial, sans-serif" font-size="11">)"
      "\n",
      num(width), num(height));
  fmt::format_to(std::back_inserter(out),
                 R"(<rect width="{}" height="{}" fill="white"/>)"
                 "\n",
                 num(width), num(height));
  if (!figure.title.empty())
    fmt::format_to(
        std::back_inserter(out),
        R"(<text class="title" x="{}" y="20" text-anchor="middle" font-size="14" font-weight="bold">{}</text>)"
        "\n",
        num(width / 2), xml_escape(figure.title));
  for (int i = 0; i < count; ++i) {
    const double left = (i % columns) * figure.panel_width, top = title + (i / columns) * figure.panel_height;
    append_panel(out, figure.panels[i], i, left, top, figure.panel_width, figure.panel_height);
  }
  if (!entries.empty())
    append_legend(out, entries, legend, figure_pad, title + rows * figure.panel_height + figure_pad / 2);
  out += "</svg>\n";
  return out;
}

}  // namespace symoro::svg
