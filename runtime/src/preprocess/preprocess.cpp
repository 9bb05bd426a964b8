#include "symoro/preprocess/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "symoro/error.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/channels.hpp"
#include "symoro/preprocess/derivatives.hpp"
#include "symoro/preprocess/resample.hpp"
#include "symoro/preprocess/time_axis.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::preprocess {

namespace {

void validate_options(const Options& o) {
  if (!(o.base_period > 0) || !(o.max_gap > 0) || o.filter_order < 1 ||
      !(o.derivative_cutoff > 0) || !(o.anti_alias_fraction > 0) || !(o.anti_alias_fraction <= 1))
    throw std::invalid_argument(
        "preprocess options: base_period, max_gap, derivative_cutoff must be positive, "
        "filter_order >= 1 and anti_alias_fraction in (0, 1]");
}

void validate_signals(const io::Log& log, const std::string& source) {
  const Eigen::Index n = log.time.size();
  if (log.q.cols() == 0)
    throw DataError(source, 0, "the log has no measured q (a reference file?)");
  if (log.tau.cols() != log.q.cols())
    throw DataError(source, 0,
                    fmt::format("{} q columns but {} tau columns", log.q.cols(), log.tau.cols()));
  if (log.q.rows() != n || log.tau.rows() != n)
    throw DataError(
        source, 0,
        fmt::format("{} time stamps but {} q and {} tau rows", n, log.q.rows(), log.tau.rows()));
  for (const auto& [name, m] : {std::pair{"q", &log.q}, std::pair{"tau", &log.tau}}) {
    if (m->allFinite()) continue;
    Eigen::Index row = 0;
    while (m->row(row).allFinite()) ++row;
    throw DataError(source, 0, fmt::format("{} of sample {} is not finite", name, row));
  }
}

// One piece on the target grid.
struct PieceSamples {
  int piece = 0;                   // index in StampAnalysis::pieces
  std::vector<long> target_index;  // multiples of the stride, in base-grid indices
  Eigen::MatrixXd q, qd, qdd, tau;
};

}  // namespace

Samples preprocess(const io::Log& log, double interval, const Options& options) {
  const std::string source = log.meta.trajectory.empty() ? "log" : log.meta.trajectory;
  validate_options(options);
  const int stride = target_stride(interval, options.base_period, source);
  validate_signals(log, source);

  Samples out;
  out.interval = interval;
  Report& report = out.report;
  report.raw_samples = log.samples();
  const StampAnalysis stamps =
      analyse_stamps(log.time, options.base_period, options.max_gap, source);
  report.irregular_stamps = stamps.irregular_stamps;
  report.gaps_bridged = stamps.gaps_bridged;
  report.missing_samples = stamps.missing_samples;
  report.pieces = static_cast<int>(stamps.pieces.size());
  report.max_stamp_deviation = stamps.max_deviation;

  // One filter for q and tau alike, so the regressor and the torque see the same low-pass.
  report.cutoff = std::min(options.derivative_cutoff, options.anti_alias_fraction * 0.5 / interval);
  const auto sections =
      butterworth_lowpass(options.filter_order, report.cutoff, 1 / options.base_period);
  const int padding = zero_phase_padding(sections);
  const int min_samples = std::max(padding + 1, 4);  // padding < length; 4 for the differences

  const Eigen::Index joints = log.joints();
  std::vector<PieceSamples> kept;
  int longest = 0;
  for (std::size_t k = 0; k < stamps.pieces.size(); ++k) {
    const StampPiece& piece = stamps.pieces[k];
    longest = std::max(longest, piece.grid_samples());
    if (piece.raw_samples() < 2 || piece.grid_samples() < min_samples) {
      ++report.dropped_pieces;
      report.dropped_samples += piece.raw_samples();
      continue;
    }
    // q and tau through the same interpolation and the same filter.
    const GridInterpolation interpolation = grid_interpolation(log.time, stamps, piece);
    Channels q = interpolation.apply(log.q);
    Channels tau = interpolation.apply(log.tau);
    filtfilt(sections, padding, q);
    filtfilt(sections, padding, tau);

    const std::vector<int> rows = target_rows(piece.first_index, piece.grid_samples(), stride);
    Derivatives d = finite_differences(q, options.base_period, rows);
    PieceSamples p;
    p.piece = static_cast<int>(k);
    p.q.resize(rows.size(), joints);
    p.tau.resize(rows.size(), joints);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      p.target_index.push_back(piece.first_index + rows[i]);
      p.q.row(i) = q.row(rows[i]);
      p.tau.row(i) = tau.row(rows[i]);
    }
    p.qd = std::move(d.first);
    p.qdd = std::move(d.second);
    kept.push_back(std::move(p));
  }
  if (kept.empty())
    throw DataError(source, 0,
                    fmt::format("log too short for the filter: the longest piece has {} samples "
                                "of {} s, a {:.3g} Hz order-{} zero-phase filter needs at least {}",
                                longest, options.base_period, report.cutoff, options.filter_order,
                                min_samples));

  Eigen::Index total = 0;
  for (const PieceSamples& p : kept) total += p.q.rows();
  out.time.resize(total);
  out.q.resize(total, joints);
  out.qd.resize(total, joints);
  out.qdd.resize(total, joints);
  out.tau.resize(total, joints);
  out.piece.reserve(total);
  Eigen::Index row = 0;
  for (const PieceSamples& p : kept) {
    const Eigen::Index n = p.q.rows();
    for (Eigen::Index i = 0; i < n; ++i)
      out.time[row + i] = stamps.t0 + static_cast<double>(p.target_index[i] / stride) * interval;
    out.q.middleRows(row, n) = p.q;
    out.qd.middleRows(row, n) = p.qd;
    out.qdd.middleRows(row, n) = p.qdd;
    out.tau.middleRows(row, n) = p.tau;
    out.piece.insert(out.piece.end(), n, p.piece);
    row += n;
  }
  report.kept_samples = static_cast<int>(total);
  return out;
}

std::string Report::summary() const {
  std::string line = fmt::format(
      "{} raw samples (stamps within {:.3f} ms of the grid, {} irregular intervals), {} gaps "
      "bridged ({} samples filled in), {} piece{}",
      raw_samples, max_stamp_deviation * 1e3, irregular_stamps, gaps_bridged, missing_samples,
      pieces, pieces == 1 ? "" : "s");
  if (dropped_pieces > 0)
    line += fmt::format(" ({} too short for the filter dropped with {} samples)", dropped_pieces,
                        dropped_samples);
  line += fmt::format(", low-pass {:.3g} Hz, {} samples kept", cutoff, kept_samples);
  return line;
}

}  // namespace symoro::preprocess
