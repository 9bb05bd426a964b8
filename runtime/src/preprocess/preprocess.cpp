#include "symoro/preprocess/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "symoro/error.hpp"
#include "symoro/io/import.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/channels.hpp"
#include "symoro/preprocess/derivatives.hpp"
#include "symoro/preprocess/edges.hpp"
#include "symoro/preprocess/resample.hpp"
#include "symoro/preprocess/time_axis.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::preprocess {

namespace {

void validate_options(const Options& options) {
  if (!(options.base_period >= 0) || !std::isfinite(options.base_period) || !std::isfinite(options.torque_delay) ||
      !(options.max_gap > 0) || options.filter_order < 1 || !(options.derivative_cutoff > 0) ||
      !(options.anti_alias_fraction > 0) || !(options.anti_alias_fraction <= 1))
    throw std::invalid_argument(
        "preprocess options: base_period >= 0 (0: the log's), max_gap, derivative_cutoff "
        "positive, filter_order >= 1 and anti_alias_fraction in (0, 1]");
}

bool same_row(const Eigen::MatrixXd& m, Eigen::Index k) {
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    if (std::memcmp(&m.coeffRef(k, j), &m.coeffRef(k - 1, j), sizeof(double)) != 0) return false;
  return true;
}

// Rows that repeat the previous one (Options::drop_stale). qd decides only when measured: a
// differentiated qd says nothing about the read.
std::vector<bool> stale_rows(const io::Log& log) {
  const bool measured_qd =
      log.meta.velocity == io::Velocity::measured && log.qd.cols() == log.q.cols() && log.qd.rows() == log.q.rows();
  std::vector<bool> stale(static_cast<std::size_t>(log.samples()), false);
  for (Eigen::Index k = 1; k < log.samples(); ++k) {
    if (!same_row(log.q, k) || !same_row(log.tau, k)) continue;
    if (measured_qd && (!same_row(log.qd, k) || (log.qd.row(k).array() == 0).all())) continue;  // moved, or at rest
    stale[static_cast<std::size_t>(k)] = true;
  }
  return stale;
}

// The log without the flagged rows (only what preprocessing reads).
io::Log without_rows(const io::Log& log, const std::vector<bool>& drop, bool with_qd) {
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < log.samples(); ++k)
    if (!drop[static_cast<std::size_t>(k)]) keep.push_back(k);
  io::Log out;
  out.meta = log.meta;
  const auto n = static_cast<Eigen::Index>(keep.size());
  out.time.resize(n);
  out.q.resize(n, log.q.cols());
  out.tau.resize(n, log.tau.cols());
  if (with_qd) out.qd.resize(n, log.qd.cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    out.time[i] = log.time[keep[i]];
    out.q.row(i) = log.q.row(keep[i]);
    out.tau.row(i) = log.tau.row(keep[i]);
    if (with_qd) out.qd.row(i) = log.qd.row(keep[i]);
  }
  return out;
}

// x(k) := x(k + shift) on the grid (shift in samples, any sign), linear between samples and held
// at the ends: the torque read `shift` samples later (Options::torque_delay).
void shift_later(Channels& x, double shift) {
  const Channels y = x;
  const Eigen::Index n = y.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double at = std::clamp(static_cast<double>(k) + shift, 0.0, static_cast<double>(n - 1));
    const Eigen::Index i = std::min<Eigen::Index>(static_cast<Eigen::Index>(at), n - 2 < 0 ? 0 : n - 2);
    const double w = n > 1 ? at - static_cast<double>(i) : 0.0;
    x.row(k) = n > 1 ? Eigen::RowVectorXd((1 - w) * y.row(i) + w * y.row(i + 1)) : Eigen::RowVectorXd(y.row(0));
  }
}

void validate_signals(const io::Log& log, const std::string& source) {
  const Eigen::Index n = log.time.size();
  if (log.q.cols() == 0) throw DataError(source, 0, "the log has no measured q (a reference file?)");
  if (log.tau.cols() != log.q.cols())
    throw DataError(source, 0, fmt::format("{} q columns but {} tau columns", log.q.cols(), log.tau.cols()));
  if (log.q.rows() != n || log.tau.rows() != n)
    throw DataError(source, 0, fmt::format("{} time stamps but {} q and {} tau rows", n, log.q.rows(), log.tau.rows()));
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

double base_period(const io::Log& log, const Options& options) {
  if (options.base_period > 0) return options.base_period;
  if (log.meta.sample_time > 0) return log.meta.sample_time;
  return io::median_sample_time(log.time, log.meta.trajectory.empty() ? "log" : log.meta.trajectory);
}

namespace {

// What every piece of a log is filtered with, and how its samples are chosen.
struct PieceFilter {
  const Options& options;
  const std::vector<Biquad>& sections;  // the one low-pass of q and tau
  int padding = 0, settle = 0, stride = 1;
  double interval = 0, period = 0;
  const Eigen::ArrayXd& quantum;  // q's smallest steps per joint (trim_settling)
};

// Piece k of the log on the target grid: q and tau interpolated onto the base grid and filtered
// alike, the torque delayed, the target rows within the settling time of an end where the arm
// moves left out (their times to edge_times), the derivatives of q (or the logged velocity's);
// none when no row is left.
std::optional<PieceSamples> filter_piece(const io::Log& log, const StampAnalysis& stamps, std::size_t k,
                                         const PieceFilter& f, Report& report, std::vector<double>& edge_times) {
  const StampPiece& piece = stamps.pieces[k];
  const Eigen::Index joints = log.joints();
  // q and tau through the same interpolation and the same filter.
  const GridInterpolation interpolation = grid_interpolation(log.time, stamps, piece);
  Channels q = interpolation.apply(log.q);
  Channels tau = interpolation.apply(log.tau);
  // Whether the arm moves at each end, judged on q before the filter (edges.hpp).
  const int reach = std::min(f.settle, piece.grid_samples());
  const bool start_moves = f.options.trim_settling && moving_at_end(q, reach, true, f.quantum);
  const bool end_moves = f.options.trim_settling && moving_at_end(q, reach, false, f.quantum);
  report.moving_ends += int(start_moves) + int(end_moves);
  filtfilt(f.sections, f.padding, q);
  if (f.options.filter_torque) filtfilt(f.sections, f.padding, tau);
  if (f.options.torque_delay != 0) shift_later(tau, f.options.torque_delay / f.period);

  std::vector<int> rows = target_rows(piece.first_index, piece.grid_samples(), f.stride);
  if (start_moves || end_moves) {
    std::vector<int> kept_rows;
    const int last = piece.grid_samples() - 1;
    for (int r : rows) {
      if ((start_moves && r < f.settle) || (end_moves && r > last - f.settle))
        edge_times.push_back(stamps.t0 + static_cast<double>((piece.first_index + r) / f.stride) * f.interval);
      else
        kept_rows.push_back(r);
    }
    rows = std::move(kept_rows);
  }
  if (rows.empty()) return std::nullopt;  // all of it within the settling time of a moving end
  Derivatives d = finite_differences(q, f.period, rows);
  if (f.options.use_logged_velocity) {
    // The logged velocity through the filter q had; its difference is the acceleration.
    Channels qd = interpolation.apply(log.qd);
    filtfilt(f.sections, f.padding, qd);
    Derivatives v = finite_differences(qd, f.period, rows);
    for (std::size_t i = 0; i < rows.size(); ++i) d.first.row(static_cast<Eigen::Index>(i)) = qd.row(rows[i]);
    d.second = std::move(v.first);
  }
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
  return p;
}

// The kept pieces' samples one after another into out, at their target times; their count.
Eigen::Index gather(const std::vector<PieceSamples>& kept, double t0, int stride, double interval, Eigen::Index joints,
                    Samples& out) {
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
      out.time[row + i] = t0 + static_cast<double>(p.target_index[i] / stride) * interval;
    out.q.middleRows(row, n) = p.q;
    out.qd.middleRows(row, n) = p.qd;
    out.qdd.middleRows(row, n) = p.qdd;
    out.tau.middleRows(row, n) = p.tau;
    out.piece.insert(out.piece.end(), n, p.piece);
    row += n;
  }
  return total;
}

// preprocess() of a whole log; the times of the target samples left out in the settling time at
// a moving end go to edge_times.
Samples preprocess_whole(const io::Log& raw, double interval, const Options& options, std::vector<double>& edge_times) {
  const std::string source = raw.meta.trajectory.empty() ? "log" : raw.meta.trajectory;
  validate_options(options);
  const double period = base_period(raw, options);
  const std::string origin = options.base_period > 0    ? "set in the options"
                             : raw.meta.sample_time > 0 ? "the log's sample_time"
                                                        : "the log's median stamp interval";
  const int stride = target_stride(interval, period, source, origin);
  validate_signals(raw, source);
  if (options.use_logged_velocity) {
    if (raw.meta.velocity == io::Velocity::differentiated)
      throw DataError(source, 0,
                      "the log's velocity was differentiated from q at import, not measured: "
                      "it cannot stand for a logged velocity (use_logged_velocity)");
    if (raw.qd.cols() != raw.q.cols() || raw.qd.rows() != raw.q.rows() || !raw.qd.allFinite())
      throw DataError(source, 0,
                      "use_logged_velocity: the log's qd is missing, of another shape than q, or not finite");
  }

  Samples out;
  out.interval = interval;
  Report& report = out.report;
  report.raw_samples = raw.samples();
  report.base_period = period;
  // Stale rows become missing samples of the time axis: the rest of the pipeline never sees them.
  io::Log fresh_log;
  if (options.drop_stale) {
    const std::vector<bool> stale = stale_rows(raw);
    report.stale_rows = static_cast<int>(std::count(stale.begin(), stale.end(), true));
    if (report.stale_rows > 0) fresh_log = without_rows(raw, stale, options.use_logged_velocity);
  }
  const io::Log& log = report.stale_rows > 0 ? fresh_log : raw;
  const StampAnalysis stamps = analyse_stamps(log.time, period, options.max_gap, source);
  report.irregular_stamps = stamps.irregular_stamps;
  report.gaps_bridged = stamps.gaps_bridged;
  report.missing_samples = stamps.missing_samples;
  report.pieces = static_cast<int>(stamps.pieces.size());
  report.max_stamp_deviation = stamps.max_deviation;

  // One filter for q and tau alike, so the regressor and the torque see the same low-pass.
  report.cutoff = std::min(options.derivative_cutoff, options.anti_alias_fraction * 0.5 / interval);
  const auto sections = butterworth_lowpass(options.filter_order, report.cutoff, 1 / period);
  const int padding = zero_phase_padding(sections);
  const int min_samples = std::max(padding + 1, 4);  // padding < length; 4 for the differences
  const int settle = settling_samples(sections);
  report.settling_seconds = settle * period;
  const Eigen::ArrayXd quantum = options.trim_settling ? smallest_steps(log.q) : Eigen::ArrayXd();
  const PieceFilter f{options, sections, padding, settle, stride, interval, period, quantum};

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
    std::optional<PieceSamples> p = filter_piece(log, stamps, k, f, report, edge_times);
    if (!p) continue;  // all of it within the settling time of a moving end
    kept.push_back(std::move(*p));
  }
  if (kept.empty() && !edge_times.empty())
    throw DataError(source, 0,
                    fmt::format("log too short: every sample lies within the {:.3g} s settling time of the {:.3g} Hz "
                                "filter at an end where the arm moves ({} samples)",
                                report.settling_seconds, report.cutoff, edge_times.size()));
  if (kept.empty())
    throw DataError(source, 0,
                    fmt::format("log too short for the filter: the longest piece has {} samples "
                                "of {} s, a {:.3g} Hz order-{} zero-phase filter needs at least {}",
                                longest, period, report.cutoff, options.filter_order, min_samples));

  const Eigen::Index total = gather(kept, stamps.t0, stride, interval, joints, out);
  report.kept_samples = static_cast<int>(total);
  report.edge_samples = static_cast<int>(edge_times.size());
  return out;
}

// The file `log` was cut from, when its rows are that file's rows file_row.. (same q, tau and qd,
// the same sample_time, stamps moved by one offset: a caller may count time from the window's
// start): else null, and the window is filtered alone.
const io::Log* source_file(const io::Log& log) {
  const io::Log* file = log.file.get();
  const Eigen::Index n = log.samples(), first = log.file_row;
  if (!file || n == 0 || first < 0 || first + n > file->samples() || file->joints() != log.joints() ||
      file->qd.cols() != log.qd.cols() || file->meta.sample_time != log.meta.sample_time)
    return nullptr;
  const double offset = log.time(0) - file->time(first);
  for (Eigen::Index k = 0; k < n; ++k)
    if (std::abs(file->time(first + k) + offset - log.time(k)) > 1e-9 * std::max(1.0, std::abs(log.time(k))))
      return nullptr;
  const auto same = [&](const Eigen::MatrixXd& window, const Eigen::MatrixXd& whole) {
    return window.rows() == n && whole.rows() == file->samples() &&
           (window.array() == whole.middleRows(first, n).array()).all();
  };
  if (!same(log.q, file->q) || !same(log.tau, file->tau) || (log.qd.cols() > 0 && !same(log.qd, file->qd)))
    return nullptr;
  return file;
}

}  // namespace

Samples preprocess(const io::Log& log, double interval, const Options& options) {
  std::vector<double> edge_times;
  const io::Log* file = source_file(log);
  if (!file) return preprocess_whole(log, interval, options, edge_times);
  // The whole file, on its own clock; then the samples on the base-grid points of the window's
  // first to last rows.
  Samples all = preprocess_whole(*file, interval, options, edge_times);
  const double period = all.report.base_period, t0 = file->time(0);
  const auto grid_index = [&](double t) { return std::llround((t - t0) / period); };
  const long long first = grid_index(file->time(log.file_row)),
                  last = grid_index(file->time(log.file_row + log.samples() - 1));
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < all.time.size(); ++k)
    if (const long long i = grid_index(all.time(k)); first <= i && i <= last) keep.push_back(k);
  if (keep.empty())
    throw DataError(log.meta.trajectory.empty() ? "log" : log.meta.trajectory, 0,
                    fmt::format("no sample at {} s intervals is left within the window [{}, {}] s", interval,
                                log.time(0), log.time(log.samples() - 1)));
  Samples out;
  out.interval = interval;
  // Times from the window's first stamp, on the caller's clock, in whole base periods, as a log cut
  // there has them (a closed loop's cycle 0 is that row): the grid point of that row, not the
  // file's first stamp, is the origin (they differ by the row's stamp jitter).
  out.time.resize(static_cast<Eigen::Index>(keep.size()));
  for (std::size_t k = 0; k < keep.size(); ++k)
    out.time(static_cast<Eigen::Index>(k)) =
        log.time(0) + static_cast<double>(grid_index(all.time(keep[k])) - first) * period;
  for (auto [to_m, from_m] : {std::pair{&out.q, &all.q}, std::pair{&out.qd, &all.qd}, std::pair{&out.qdd, &all.qdd},
                              std::pair{&out.tau, &all.tau}})
    *to_m = (*from_m)(keep, Eigen::all);
  for (Eigen::Index k : keep) out.piece.push_back(all.piece[static_cast<std::size_t>(k)]);
  out.report = all.report;
  out.report.raw_samples = log.samples();
  out.report.context_rows = file->samples() - log.samples();
  out.report.kept_samples = static_cast<int>(keep.size());
  // The window's share of the edges: the file's ends it reaches.
  const long long middle = (first + last) / 2;
  int before = 0, after = 0;
  for (double t : edge_times)
    if (const long long i = grid_index(t); first <= i && i <= last) ++(i < middle ? before : after);
  out.report.edge_samples = before + after;
  out.report.moving_ends = int(before > 0) + int(after > 0);
  return out;
}

std::string Report::summary() const {
  std::string line = fmt::format(
      "{} raw samples on a {:.6g} ms grid (stamps within {:.3f} ms of it, {} irregular "
      "intervals), {} stale rows left out, {} gaps bridged ({} samples filled in), {} piece{}",
      raw_samples, base_period * 1e3, max_stamp_deviation * 1e3, irregular_stamps, stale_rows, gaps_bridged,
      missing_samples, pieces, pieces == 1 ? "" : "s");
  if (dropped_pieces > 0)
    line += fmt::format(" ({} too short for the filter dropped with {} samples)", dropped_pieces, dropped_samples);
  line += fmt::format(", low-pass {:.3g} Hz", cutoff);
  if (context_rows > 0) line += fmt::format(", filtered with the {} rows of its file around it", context_rows);
  if (edge_samples > 0)
    line += fmt::format(", {} samples within the filter's settling time ({:.3g} s) of {} moving end{} left out",
                        edge_samples, settling_seconds, moving_ends, moving_ends == 1 ? "" : "s");
  line += fmt::format(", {} samples kept", kept_samples);
  return line;
}

}  // namespace symoro::preprocess
