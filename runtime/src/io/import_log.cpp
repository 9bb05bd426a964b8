// One exported file to a project log: columns by the mapping, units to SI, repeated samples
// sorted into stale rows (kept) and duplicates (dropped), the velocity differentiated when the
// file has none.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <fmt/format.h>

#include "import_detail.hpp"
#include "symoro/error.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/number_text.hpp"

namespace symoro::io {

namespace {

constexpr double kPi = 3.14159265358979323846;

bool same_bits(const double* a, const double* b, std::size_t count) {
  return std::memcmp(a, b, count * sizeof(double)) == 0;
}

struct Group {
  std::string key;  // "q", ...
  std::vector<int> columns;
  std::size_t offset;  // first value of the group in a parsed row
};

void check_mapping(const ImportMapping& m) {
  const auto fail = [&](const std::string& key, const std::string& message) {
    throw DataError(m.origin, detail::mapping_line(m, key), message);
  };
  if (m.time.empty()) fail("time", "the mapping has no time column");
  if (m.q.empty()) fail("q", "the mapping has no q columns");
  if (m.tau.empty()) fail("tau", "the mapping has no tau columns");
  const int references = !m.q_ref.empty() + !m.qd_ref.empty() + !m.qdd_ref.empty();
  if (references != 0 && references != 3)
    fail(m.q_ref.empty() ? (m.qd_ref.empty() ? "qdd_ref" : "qd_ref") : "q_ref",
         "q_ref, qd_ref and qdd_ref come together or not at all");
  if (!std::isfinite(m.torque_scale) || m.torque_scale == 0)
    fail("units.torque_scale", "the torque scale is not a finite non-zero number");
}

}  // namespace

double median_sample_time(const Eigen::VectorXd& time, const std::string& source) {
  if (time.size() < 2)
    throw DataError(source, 0, fmt::format("{} time stamps: a sample time needs at least 2", time.size()));
  std::vector<double> intervals(static_cast<std::size_t>(time.size() - 1));
  for (Eigen::Index k = 1; k < time.size(); ++k) intervals[k - 1] = time[k] - time[k - 1];
  const auto middle = intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2);
  std::nth_element(intervals.begin(), middle, intervals.end());
  const double us = std::round(*middle * 1e6);
  if (!(us >= 1))
    throw DataError(source, 0, fmt::format("the median stamp interval {} s rounds to 0 us", number_text(*middle)));
  return us / 1e6;
}

Eigen::MatrixXd differentiate_positions(const Eigen::VectorXd& time, const Eigen::MatrixXd& q,
                                        const std::vector<bool>& skip) {
  std::vector<Eigen::Index> fresh;
  for (Eigen::Index k = 0; k < time.size(); ++k)
    if (!skip[static_cast<std::size_t>(k)]) fresh.push_back(k);
  Eigen::MatrixXd qd = Eigen::MatrixXd::Zero(q.rows(), q.cols());
  const std::size_t m = fresh.size();
  if (m < 2) return qd;
  for (std::size_t i = 0; i < m; ++i) {
    const Eigen::Index k = fresh[i];
    if (m == 2) {
      qd.row(k) = (q.row(fresh[1]) - q.row(fresh[0])) / (time[fresh[1]] - time[fresh[0]]);
      continue;
    }
    // The parabola through three neighbours a, b, c (the row in the middle, or at an end),
    // differentiated at the row: Lagrange weights, times taken from b to keep them small.
    const std::size_t mid = std::clamp<std::size_t>(i, 1, m - 2);
    const Eigen::Index a = fresh[mid - 1], b = fresh[mid], c = fresh[mid + 1];
    const double ta = time[a] - time[b], tc = time[c] - time[b], x = time[k] - time[b];
    const double wa = (2 * x - tc) / (ta * (ta - tc));
    const double wb = (2 * x - ta - tc) / (ta * tc);
    const double wc = (2 * x - ta) / (tc * (tc - ta));
    qd.row(k) = wa * q.row(a) + wb * q.row(b) + wc * q.row(c);
  }
  // A stale row repeats the state read before it, velocity included.
  for (Eigen::Index k = 1; k < time.size(); ++k)
    if (skip[static_cast<std::size_t>(k)]) qd.row(k) = qd.row(k - 1);
  return qd;
}

namespace {

// Every mapped column once, in group order: time, q, [qd], tau, [q_ref, qd_ref, qdd_ref]; a
// column two groups select is an error at the header.
struct Columns {
  std::vector<Group> groups;
  std::vector<int> columns;  // the table's columns, group after group
  const Group* group(const std::string& key) const {
    for (const Group& g : groups)
      if (g.key == key) return &g;
    return nullptr;
  }
};

Columns select_columns(const detail::TextTable& table, const ImportMapping& mapping, const ImportTarget& target,
                       int n) {
  Columns out;
  std::vector<Group>& groups = out.groups;
  std::vector<int>& columns = out.columns;
  for (const auto& [key, selector] : std::vector<std::pair<std::string, std::string>>{{"time", mapping.time},
                                                                                      {"q", mapping.q},
                                                                                      {"qd", mapping.qd},
                                                                                      {"tau", mapping.tau},
                                                                                      {"q_ref", mapping.q_ref},
                                                                                      {"qd_ref", mapping.qd_ref},
                                                                                      {"qdd_ref", mapping.qdd_ref}}) {
    if (selector.empty()) continue;
    Group g{key, detail::resolve_selector(selector, key, key == "time" ? 1 : n, table, mapping, target),
            columns.size()};
    for (int c : g.columns) {
      const auto used = std::find(columns.begin(), columns.end(), c);
      if (used != columns.end()) {
        const auto& owner = *std::find_if(groups.begin(), groups.end(), [&](const Group& o) {
          return static_cast<std::size_t>(used - columns.begin()) >= o.offset &&
                 static_cast<std::size_t>(used - columns.begin()) < o.offset + o.columns.size();
        });
        throw DataError(table.file(), table.has_header() ? table.header_line() : table.first_line(),
                        fmt::format("{} and {} both select {} (mapping: {})", owner.key, key, table.column_label(c),
                                    mapping.origin));
      }
      columns.push_back(c);
    }
    groups.push_back(std::move(g));
  }
  return out;
}

// The parsed rows kept, in order, and whether each is stale: a row with the previous kept row's
// time and values is a duplicate (dropped, its line noted), with its time but other values an
// error; a later row whose measured values (those before measured_end) repeat the previous
// row's is stale (kept, noted). Time going backwards is an error.
struct KeptRows {
  std::vector<std::size_t> rows;
  std::vector<bool> stale;
};

KeptRows keep_rows(const detail::TextTable& table, const std::vector<int>& columns, const std::vector<double>& values,
                   const std::vector<int>& lines, std::size_t measured_end, double divisor, ImportedLog& out) {
  const std::string& file = table.file();
  const std::size_t width = columns.size();
  KeptRows k;
  std::vector<std::size_t>& kept = k.rows;
  std::vector<bool>& stale = k.stale;
  for (std::size_t r = 0; r < lines.size(); ++r) {
    const double* row = values.data() + r * width;
    if (kept.empty()) {
      kept.push_back(r);
      stale.push_back(false);
      continue;
    }
    const std::size_t p = kept.back();
    const double* previous = values.data() + p * width;
    const double t = row[0] / divisor, t_previous = previous[0] / divisor;
    if (t < t_previous)
      throw DataError(file, lines[r],
                      fmt::format("time goes backwards: {} s here, {} s on line {}", number_text(t),
                                  number_text(t_previous), lines[p]));
    if (t == t_previous) {
      if (same_bits(row + 1, previous + 1, width - 1)) {
        out.duplicate_lines.push_back(lines[r]);
        continue;
      }
      std::size_t c = 1;
      while (c + 1 < width && same_bits(row + c, previous + c, 1)) ++c;
      throw DataError(
          file, lines[r],
          fmt::format("same time stamp as line {} ({} s) but other values: {} is {} here, {} there", lines[p],
                      number_text(t), table.column_label(columns[c]), number_text(row[c]), number_text(previous[c])));
    }
    const bool repeated = same_bits(row + 1, previous + 1, measured_end - 1);
    if (repeated) out.stale_lines.push_back(lines[r]);
    kept.push_back(r);
    stale.push_back(repeated);
  }
  return k;
}

// The kept rows' times in s. Stamps far from 0 (1e15 ms since an epoch) hold no 1 ms step in
// double precision once in s (read as 0.977 ms): then the times count from the first stamp, the
// difference taken in the file's unit, where it is exact. Returns whether they were rebased.
bool fill_times(const std::vector<double>& values, std::size_t width, const std::vector<std::size_t>& kept,
                double divisor, Eigen::VectorXd& time) {
  const Eigen::Index rows = static_cast<Eigen::Index>(kept.size());
  time.resize(rows);
  for (Eigen::Index k = 0; k < rows; ++k) time[k] = values[kept[static_cast<std::size_t>(k)] * width] / divisor;
  bool rebased = false;
  if (rows >= 2) {
    std::vector<double> steps;
    for (std::size_t i = 1; i < kept.size(); ++i)
      steps.push_back(values[kept[i] * width] - values[kept[i - 1] * width]);
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
    const double step = steps[steps.size() / 2] / divisor;
    const double t_max = std::max(std::abs(time[0]), std::abs(time[rows - 1]));
    rebased = std::nextafter(t_max, INFINITY) - t_max > 1e-4 * step;
  }
  if (rebased) {
    const double first = values[kept[0] * width];
    for (Eigen::Index k = 0; k < rows; ++k)
      time[k] = (values[kept[static_cast<std::size_t>(k)] * width] - first) / divisor;
  }
  return rebased;
}

}  // namespace

ImportedLog import_log(const std::filesystem::path& input, const ImportMapping& mapping, const ImportTarget& target) {
  check_mapping(mapping);
  const int n = static_cast<int>(target.joints.size());
  if (n == 0) throw DataError(input.string(), 0, "the robot has no joints");
  if (!target.prismatic.empty() && static_cast<int>(target.prismatic.size()) != n)
    throw DataError(input.string(), 0, "the prismatic flags do not match the joint list");
  const detail::TextTable table(input, mapping.delimiter, mapping.header);
  const std::string& file = table.file();

  const Columns selected = select_columns(table, mapping, target, n);
  const std::vector<int>& columns = selected.columns;
  const auto group = [&](const std::string& key) { return selected.group(key); };
  const bool has_qd = group("qd") != nullptr;
  const bool has_refs = group("q_ref") != nullptr;
  // Measured values end where the references begin: they decide a stale row.
  const std::size_t width = columns.size();
  const std::size_t measured_end = has_refs ? group("q_ref")->offset : width;

  std::vector<double> values;
  std::vector<int> lines;
  table.read(columns, values, lines);

  ImportedLog out;
  out.input = input;
  out.rows = static_cast<int>(lines.size());
  const double divisor = detail::time_divisor(mapping.time_unit);
  const KeptRows kept_rows = keep_rows(table, columns, values, lines, measured_end, divisor, out);
  const std::vector<std::size_t>& kept = kept_rows.rows;
  const std::vector<bool>& stale = kept_rows.stale;

  Log& log = out.log;
  const Eigen::Index rows = static_cast<Eigen::Index>(kept.size());
  const auto fill = [&](const Group* g, Eigen::MatrixXd& m, bool torque) {
    m.resize(rows, g ? n : 0);
    if (!g) return;
    for (int j = 0; j < n; ++j) {
      const bool prismatic = !target.prismatic.empty() && target.prismatic[static_cast<std::size_t>(j)];
      // Angles, and their rates per second, to rad; prismatic joints are in m already.
      const double scale = torque ? mapping.torque_scale : 1.0;
      const bool degrees = !torque && !prismatic && mapping.angle_unit == AngleUnit::deg;
      for (Eigen::Index k = 0; k < rows; ++k) {
        const double v = values[kept[static_cast<std::size_t>(k)] * width + g->offset + static_cast<std::size_t>(j)];
        m(k, j) = degrees ? v * (kPi / 180) : v * scale;
      }
    }
  };
  const bool rebased = fill_times(values, width, kept, divisor, log.time);
  for (std::size_t r : kept) out.lines.push_back(lines[r]);
  fill(group("q"), log.q, false);
  fill(group("tau"), log.tau, true);
  fill(group("q_ref"), log.q_ref, false);
  fill(group("qd_ref"), log.qd_ref, false);
  fill(group("qdd_ref"), log.qdd_ref, false);
  if (has_qd) {
    fill(group("qd"), log.qd, false);
  } else {
    const long fresh = std::count(stale.begin(), stale.end(), false);
    if (fresh < 3)
      throw DataError(
          file, lines.back(),
          fmt::format("{} distinct samples: differentiating q (the file has no qd) needs at least 3", fresh));
    log.qd = differentiate_positions(log.time, log.q, stale);
  }
  if (rows < 2) throw DataError(file, lines.back(), "one sample: a log needs at least 2 (with distinct time stamps)");

  LogMetadata& meta = log.meta;
  meta.robot = target.robot;
  meta.trajectory = input.stem().string();
  meta.trial = 1;
  meta.source = "robot";
  meta.joints = target.joints;
  meta.sample_time = median_sample_time(log.time, file);
  meta.velocity = has_qd ? Velocity::measured : Velocity::differentiated;
  meta.notes =
      fmt::format("imported from {}: {} rows, {} stale rows kept, {} duplicate rows dropped{}",
                  input.filename().string(), out.rows, out.stale_lines.size(), out.duplicate_lines.size(),
                  has_qd ? "" : "; qd differentiated from q") +
      (rebased ? fmt::format("; time counted from the first stamp ({} {} in the file: too large for the sample "
                             "time in double precision)",
                             number_text(values[kept[0] * width]), detail::time_unit_name(mapping.time_unit))
               : std::string());
  for (const Group& g : selected.groups)
    for (std::size_t j = 0; j < g.columns.size(); ++j)
      out.columns[g.key == "time" ? "time" : g.key + std::to_string(j + 1)] = table.column_label(g.columns[j]);
  return out;
}

}  // namespace symoro::io
