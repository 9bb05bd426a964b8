// A small SVG plotting module for the study report: panels of scatter points, lines or grouped
// bars on axes with round ("nice") ticks, point labels, and one legend shared by the figure,
// laid out in a grid. The output is one self-contained SVG document (standard library and fmt
// only), so a report's figures need no plotting tool.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace symoro::svg {

// Axis ticks: a round step (1, 2 or 5 times a power of ten) and every multiple of it from the
// largest one <= lo to the smallest one >= hi, so the ticks always cover [lo, hi].
struct Ticks {
  double step = 1;
  int decimals = 0;            // digits after the point that show every tick exactly
  std::vector<double> values;  // ascending; values.front() <= lo, values.back() >= hi
};

// About `intervals` steps over [lo, hi] (the step is the round value nearest (hi - lo) /
// intervals). An empty range is widened around its value; non-finite input gives [0, 1].
Ticks nice_ticks(double lo, double hi, int intervals = 5);

// A tick's label with `decimals` digits after the point, never "-0".
std::string tick_text(double value, int decimals);

enum class Marker { circle, square, triangle, diamond, cross };

struct Style {
  std::string colour = "#1f77b4";
  Marker marker = Marker::circle;  // points only
  double size = 3.5;               // marker radius, px
  double width = 1.5;              // line width, px
  std::string dash;                // line stroke-dasharray, e.g. "5 3"; empty: solid
  double opacity = 0.85;           // marker and bar fill
};

struct Series {
  std::string name;  // legend entry (one entry per distinct name and kind); empty: none
  Style style;
  // Points and lines: the pairs (x[i], y[i]); a non-finite pair is left out (a line breaks
  // there). Bars: y[i] is the bar of category i, x is unused.
  std::vector<double> x, y;
};

// Text next to a data point, optionally with a ring around the point (a highlighted one).
struct PointLabel {
  double x = 0, y = 0;
  std::string text;
  bool ring = false;
  std::string colour = "#000000";
};

struct Range {
  double lo = 0, hi = 1;
};

struct Panel {
  std::string title, x_label, y_label;
  std::vector<Series> points;           // drawn as markers
  std::vector<Series> lines;            // drawn as polylines
  std::vector<std::string> categories;  // with bars: the x axis is these groups
  std::vector<Series> bars;             // one bar per series in each category's group
  std::vector<PointLabel> labels;
  // What the axes must cover instead of this panel's own data (e.g. the union of several
  // panels' data, so they share axes); either way the axis is widened to its ticks.
  std::optional<Range> x_range, y_range;
};

struct Figure {
  std::string title;
  std::vector<Panel> panels;
  int columns = 0;                               // panels per row; 0: all in one row
  double panel_width = 340, panel_height = 280;  // px, each panel including its axes' margins
  bool legend = true;
};

// The SVG document. Every plotted point is one element of class "marker", every bar one of
// class "bar"; tick labels have class "xtick" / "ytick" ("category" on a bar axis), and each
// panel is a <g class="panel"> (so tests and tools can count and read them back).
std::string render(const Figure& figure);

// Text safe inside an SVG/XML element or attribute.
std::string xml_escape(const std::string& text);

}  // namespace symoro::svg
