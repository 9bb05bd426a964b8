// The localization stage's output for people: a Markdown section (one table row per joint, the
// per-joint summaries, the residual per regime and per frequency band) and SVG figures drawn
// with the study report's writer (identify/svg_plot.hpp), written atomically.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "symoro/diagnose/localize.hpp"

namespace symoro::diagnose {

// The section, headed "<#...#> <title>" at `heading_level` (its sub-tables one level deeper).
// `figures` are links relative to the Markdown file (e.g. "figures/" + a name returned by
// write_localization_figures); each is embedded with a caption matching its kind.
std::string localization_markdown(const Localization& localization, const std::vector<std::string>& figures = {},
                                  const std::string& title = "Where the residual is", int heading_level = 2);

struct LocalizationFigureOptions {
  std::string time_trajectory;  // the series name plotted against time; empty: the first series
  int max_points = 2000;        // scatter points per panel (uniform stride over the samples)
  int max_line_points = 4000;   // polyline points per panel (min/max per bucket keeps the peaks)
};

// Writes into `dir` (created if missing), one panel per joint in each:
//   <prefix>_residual_velocity.svg  r vs qd, decimated scatter and the binned mean (friction)
//   <prefix>_residual_spectrum.svg  log10 of the residual and measured-torque PSD vs frequency
//                                   (svg_plot has linear axes only; the axis label says log10)
//   <prefix>_residual_time.svg      r vs time for one trajectory (its pieces, gaps left open)
// (without "<prefix>_" when prefix is empty). A figure without data (no spectrum, no series of
// that name) is not written. Returns the file names written, relative to `dir`.
std::vector<std::string> write_localization_figures(const std::vector<ResidualSeries>& series,
                                                    const Localization& localization, const std::filesystem::path& dir,
                                                    const std::string& prefix,
                                                    const LocalizationFigureOptions& options = {});

}  // namespace symoro::diagnose
