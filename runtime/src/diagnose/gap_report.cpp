#include "symoro/diagnose/gap_report.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "symoro/diagnose/localize.hpp"
#include "symoro/diagnose/localize_report.hpp"
#include "symoro/report/svg_plot.hpp"
#include "symoro/io/atomic_file.hpp"

namespace symoro::diagnose {

namespace {

using study::StudyValidation;
using study::ValidationRecord;

const ValidationRecord* find(const StudyValidation& s, const std::string& trajectory) {
  for (const auto& v : s.records)
    if (v.trajectory == trajectory) return &v;
  return nullptr;
}

std::string model_name(const std::string& m) { return m.empty() ? "full" : m; }

// rms per joint of measured - simulated over finite rows (a diverged simulation leaves NaN).
Eigen::VectorXd sum_squares(const ValidationRecord& v, int& rows) {
  const Eigen::Index n = v.tau_measured.cols();
  Eigen::VectorXd s = Eigen::VectorXd::Zero(n);
  rows = 0;
  for (Eigen::Index i = 0; i < v.tau_measured.rows(); ++i) {
    const Eigen::RowVectorXd e = v.tau_measured.row(i) - v.tau_rescue.row(i);
    if (!e.allFinite()) {
      s.setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    s += e.array().square().matrix().transpose();
    ++rows;
  }
  return s;
}

double pooled(const Eigen::VectorXd& joint) { return std::sqrt(joint.array().square().mean()); }

std::string pct(double before, double after) {
  if (!(before > 0) || !std::isfinite(after)) return "—";
  return fmt::format("{:+.1f} %", 100 * (after - before) / before);
}

svg::Series line(const Eigen::VectorXd& t, const Eigen::MatrixXd& m, int j, const std::string& name, const char* colour,
                 double width, const char* dash) {
  svg::Series s;
  s.name = name;
  s.style.colour = colour;
  s.style.width = width;
  s.style.dash = dash;
  for (Eigen::Index i = 0; i < t.size() && i < m.rows(); ++i) {
    s.x.push_back(t(i));
    s.y.push_back(m(i, j));
  }
  return s;
}

std::string joint_bars(const GapComparison& c, const GapReportOptions& options) {
  svg::Figure f;
  f.title = "Held-out torque error per joint (rms over the compared trajectories)";
  svg::Panel p;
  p.y_label = "rms(τ measured − τ simulated) [N m]";
  svg::Series b, a;
  b.name = options.before_label + " (" + c.before_model + ")";
  b.style.colour = "#999999";
  a.name = options.after_label + " (" + c.after_model + ")";
  a.style.colour = "#d62728";
  for (Eigen::Index j = 0; j < c.joint_before.size(); ++j) {
    p.categories.push_back(fmt::format("J{}", j + 1));
    b.y.push_back(c.joint_before(j));
    a.y.push_back(c.joint_after(j));
  }
  p.bars = {b, a};
  f.panels.push_back(p);
  f.panel_width = 120 + 60.0 * static_cast<double>(c.joint_before.size());
  return svg::render(f);
}

std::string torque_figure(const ValidationRecord& before, const ValidationRecord& after, const std::vector<int>& joints,
                          const GapComparison& c, const GapReportOptions& options) {
  svg::Figure f;
  f.title = before.trajectory + ": measured torque and the closed-loop simulation of each model";
  f.columns = 2;
  f.panel_width = 520;
  f.panel_height = 210;
  for (int j : joints) {
    if (j < 0 || j >= before.tau_measured.cols()) continue;
    svg::Panel p;
    p.title = fmt::format("J{}: torque", j + 1);
    p.x_label = "t [s]";
    p.y_label = "τ [N m]";
    p.lines.push_back(line(before.time, before.tau_measured, j, "measured", "#000000", 1.6, ""));
    p.lines.push_back(line(before.time, before.tau_rescue, j, options.before_label + " (" + c.before_model + ")",
                           "#999999", 1.2, "6 3"));
    p.lines.push_back(
        line(after.time, after.tau_rescue, j, options.after_label + " (" + c.after_model + ")", "#d62728", 1.1, ""));
    f.panels.push_back(p);
    svg::Panel r;
    r.title = fmt::format("J{}: error (measured − simulated)", j + 1);
    r.x_label = "t [s]";
    r.y_label = "[N m]";
    const Eigen::MatrixXd eb = before.tau_measured - before.tau_rescue, ea = after.tau_measured - after.tau_rescue;
    r.lines.push_back(line(before.time, eb, j, options.before_label + " (" + c.before_model + ")", "#999999", 1.2, ""));
    r.lines.push_back(line(after.time, ea, j, options.after_label + " (" + c.after_model + ")", "#d62728", 1.1, ""));
    f.panels.push_back(r);
  }
  return svg::render(f);
}

// The closed-loop residual (measured - accepted model's simulated torque) of the compared
// trajectories as localization series, split where the time axis has a gap.
std::vector<ResidualSeries> closed_loop_series(const StudyValidation& s, const GapComparison& c) {
  std::vector<ResidualSeries> out;
  for (const auto& t : c.trajectories) {
    const ValidationRecord* v = find(s, t.trajectory);
    const Eigen::Index rows = v->time.size();
    for (Eigen::Index a = 0; a < rows;) {
      Eigen::Index b = a + 1;
      while (b < rows && v->time(b) - v->time(b - 1) < 1.5 * v->interval) ++b;
      ResidualSeries r;
      r.name = t.trajectory;
      r.interval = v->interval;
      r.time = v->time.segment(a, b - a);
      r.q = v->q.middleRows(a, b - a);
      r.qd = v->qd.middleRows(a, b - a);
      r.qdd = v->qdd.middleRows(a, b - a);
      r.tau_measured = v->tau_measured.middleRows(a, b - a);
      r.tau_model = v->tau_rescue.middleRows(a, b - a);
      out.push_back(std::move(r));
      a = b;
    }
  }
  return out;
}

// The localization section of one model, with its figures; a note instead when the series
// cannot be localized (a diverged simulation leaves no finite residual).
std::string localization_section(const StudyValidation& s, const GapComparison& c, const std::string& label,
                                 const std::string& prefix, const std::filesystem::path& dir,
                                 std::vector<std::filesystem::path>& files) {
  const std::string title = "Where the closed-loop error is: " + label;
  try {
    const auto series = closed_loop_series(s, c);
    const Localization loc = localize(series, {});
    LocalizationFigureOptions fo;
    fo.time_trajectory = c.trajectories.back().trajectory;
    std::vector<std::string> figures;
    for (const auto& f : write_localization_figures(series, loc, dir / "figures", prefix, fo)) {
      figures.push_back("figures/" + f);
      files.push_back(dir / "figures" / f);
    }
    return localization_markdown(loc, figures, title, 2);
  } catch (const std::invalid_argument& e) {
    return "## " + title + "\n\nNot localized: " + std::string(e.what()) + ".\n\n";
  }
}

}  // namespace

GapComparison compare_studies(const StudyValidation& before, const StudyValidation& after) {
  if (before.robot != after.robot)
    throw std::invalid_argument(
        fmt::format("the studies are of different robots ('{}' and '{}')", before.robot, after.robot));
  GapComparison c;
  c.robot = before.robot;
  c.before_model = model_name(before.model);
  c.after_model = model_name(after.model);
  Eigen::VectorXd ss_before, ss_after;
  long total = 0;
  for (const auto& b : before.records) {
    const ValidationRecord* a = find(after, b.trajectory);
    if (!a) {
      c.only_before.push_back(b.trajectory);
      continue;
    }
    if (std::abs(a->interval - b.interval) > 1e-9 || a->tau_measured.rows() != b.tau_measured.rows() ||
        a->tau_measured.cols() != b.tau_measured.cols())
      throw std::invalid_argument(fmt::format(
          "{} was validated differently ({} samples at {:g} ms before, {} at {:g} ms after): rerun one study with "
          "--validation-interval",
          b.trajectory, b.tau_measured.rows(), b.interval * 1e3, a->tau_measured.rows(), a->interval * 1e3));
    if (b.tau_measured.rows() > 0 && (b.tau_measured - a->tau_measured).cwiseAbs().maxCoeff() > 1e-9)
      throw std::invalid_argument(b.trajectory + ": the measured torques differ: the studies used other data");
    if (a->kind != b.kind)
      throw std::invalid_argument(fmt::format(
          "{} was validated {} before and {} after: the errors are not comparable ({}{})", b.trajectory, b.kind,
          a->kind, b.note.empty() ? a->note : b.note, b.note.empty() || a->note.empty() ? "" : "; " + a->note));
    GapTrajectory t;
    t.trajectory = b.trajectory;
    t.kind = b.kind;
    t.interval = b.interval;
    int rows_b = 0, rows_a = 0;
    const Eigen::VectorXd sb = sum_squares(b, rows_b), sa = sum_squares(*a, rows_a);
    t.samples = static_cast<int>(b.tau_measured.rows());
    t.joint_before = (sb / std::max(1, rows_b)).cwiseSqrt();
    t.joint_after = (sa / std::max(1, rows_a)).cwiseSqrt();
    t.rmse_before = pooled(t.joint_before);
    t.rmse_after = pooled(t.joint_after);
    if (ss_before.size() == 0) {
      ss_before = Eigen::VectorXd::Zero(sb.size());
      ss_after = Eigen::VectorXd::Zero(sb.size());
    }
    ss_before += sb;
    ss_after += sa;
    total += t.samples;
    c.trajectories.push_back(std::move(t));
  }
  for (const auto& a : after.records)
    if (!find(before, a.trajectory)) c.only_after.push_back(a.trajectory);
  if (c.trajectories.empty()) throw std::invalid_argument("the studies have no validation trajectory in common");
  c.joint_before = (ss_before / static_cast<double>(std::max(1L, total))).cwiseSqrt();
  c.joint_after = (ss_after / static_cast<double>(std::max(1L, total))).cwiseSqrt();
  c.rmse_before = pooled(c.joint_before);
  c.rmse_after = pooled(c.joint_after);
  for (const auto& name : after.names)
    if (std::find(before.names.begin(), before.names.end(), name) == before.names.end()) c.added.push_back(name);
  return c;
}

GapReportOptions gap_report_options(const std::filesystem::path& before_dir, const std::filesystem::path& after_dir,
                                    const GapComparison& comparison, const std::string& trajectory,
                                    const std::vector<int>& joints) {
  GapReportOptions ro;
  ro.before_label = before_dir.filename().string();
  ro.after_label = after_dir.filename().string();
  if (ro.before_label.empty() || ro.before_label == ro.after_label)
    ro.before_label = "before", ro.after_label = "after";
  ro.figure_trajectory = trajectory;
  for (int j : joints) {
    if (j < 1 || j > comparison.joint_before.size())
      throw std::invalid_argument(fmt::format("joint {} is not in 1..{}", j, comparison.joint_before.size()));
    ro.figure_joints.push_back(j - 1);
  }
  return ro;
}

std::vector<std::filesystem::path> write_gap_report(const StudyValidation& before, const StudyValidation& after,
                                                    const GapComparison& c, const std::filesystem::path& dir,
                                                    const GapReportOptions& options) {
  std::vector<std::filesystem::path> files;
  std::filesystem::create_directories(dir / "figures");
  const std::string bl = options.before_label + " (" + c.before_model + ")",
                    al = options.after_label + " (" + c.after_model + ")";

  std::string md = fmt::format("# Model gap on held-out trajectories: {} → {}\n\n", c.before_model, c.after_model);
  md += fmt::format(
      "Robot {}. Each model was identified by its own study (OLS, PD audit, conditional SDP, CLIE where the robot has "
      "a "
      "controller description, rescue) and its accepted parameters give each held-out trajectory's torque: closed loop "
      "(the model under the experiment's FF+PD controller) or open loop (the model's inverse dynamics on the measured "
      "motion), as the table below says; the error is measured minus model torque.\n\n",
      c.robot);
  md += "| | model | parameters | selected run | final audit |\n|---|---|---|---|---|\n";
  for (const auto* s : {&before, &after})
    md += fmt::format("| {} | {} | {} | {} | {}{} |\n", s == &before ? options.before_label : options.after_label,
                      model_name(s->model), s->names.size(), s->selected_run, s->accepted ? "PD" : "NOT PD",
                      s->rescued ? " (rescued)" : "");
  md += fmt::format("\n**Held-out rms torque error: {:.4f} → {:.4f} N m ({})** over {}.\n\n", c.rmse_before,
                    c.rmse_after, pct(c.rmse_before, c.rmse_after),
                    fmt::join(
                        [&] {
                          std::vector<std::string> v;
                          for (const auto& t : c.trajectories) v.push_back(t.trajectory);
                          return v;
                        }(),
                        ", "));
  {
    // Against the raw measured torque, open loop, where both studies scored it.
    std::string rows;
    for (const auto& b : before.records)
      for (const auto& a : after.records)
        if (a.trajectory == b.trajectory && std::isfinite(a.raw_rmse_rescue) && std::isfinite(b.raw_rmse_rescue))
          rows += fmt::format("| {} | {:.4f} | {:.4f} | {} |\n", a.trajectory, b.raw_rmse_rescue, a.raw_rmse_rescue,
                              pct(b.raw_rmse_rescue, a.raw_rmse_rescue));
    if (!rows.empty())
      md += "Against the raw measured torque, open loop at the logs' own rate (" + after.records.front().raw_filter +
            "):\n\n| trajectory | rms before [N m] | rms after [N m] | change |\n|---|---|---|---|\n" + rows + "\n";
    else
      md += "Against the raw measured torque: not scored (a study written before raw-torque validation).\n\n";
  }
  if (!c.only_before.empty() || !c.only_after.empty())
    md += fmt::format("Left out (validated by one study only): {}.\n\n",
                      fmt::join(
                          [&] {
                            std::vector<std::string> v = c.only_before;
                            v.insert(v.end(), c.only_after.begin(), c.only_after.end());
                            return v;
                          }(),
                          ", "));

  md +=
      "## Per trajectory\n\n| trajectory | kind | interval | samples | rms before [N m] | rms after [N m] | change |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const auto& t : c.trajectories)
    md += fmt::format("| {} | {} | {:g} ms | {} | {:.4f} | {:.4f} | {} |\n", t.trajectory, t.kind, t.interval * 1e3,
                      t.samples, t.rmse_before, t.rmse_after, pct(t.rmse_before, t.rmse_after));

  md += "\n## Per joint\n\n| joint | rms before [N m] | rms after [N m] | change |\n|---|---|---|---|\n";
  for (Eigen::Index j = 0; j < c.joint_before.size(); ++j)
    md += fmt::format("| J{} | {:.4f} | {:.4f} | {} |\n", j + 1, c.joint_before(j), c.joint_after(j),
                      pct(c.joint_before(j), c.joint_after(j)));
  const std::string bars = "figures/gap_joints.svg";
  io::write_file_atomically(dir / bars, joint_bars(c, options));
  files.push_back(dir / bars);
  md += fmt::format("\n![rms error per joint, before and after]({})\n\n", bars);

  if (!c.added.empty()) {
    md += "## Added parameters\n\n| parameter | unit | identified |" +
          std::string(after.truth.size() ? " twin truth |" : "") + "\n|---|---|---|" +
          (after.truth.size() ? "---|" : "") + "\n";
    for (const auto& name : c.added) {
      const auto k = std::find(after.names.begin(), after.names.end(), name) - after.names.begin();
      md += fmt::format("| {} | {} | {:.5g} |", name, k < static_cast<long>(after.units.size()) ? after.units[k] : "",
                        after.phi(k));
      if (after.truth.size() > k) md += fmt::format(" {:.5g} |", after.truth(k));
      md += "\n";
    }
    md += "\n";
  }

  // Torque figure: the requested trajectory, else the last compared; the joints whose error
  // changed most unless given.
  std::string traj = options.figure_trajectory.empty() ? c.trajectories.back().trajectory : options.figure_trajectory;
  const ValidationRecord* vb = find(before, traj);
  const ValidationRecord* va = find(after, traj);
  if (!vb || !va) throw std::invalid_argument("figure trajectory " + traj + " is not validated by both studies");
  std::vector<int> joints = options.figure_joints;
  if (joints.empty()) {
    std::vector<int> order(static_cast<std::size_t>(c.joint_before.size()));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return c.joint_before(a) - c.joint_after(a) > c.joint_before(b) - c.joint_after(b);
    });
    order.resize(std::min<std::size_t>(3, order.size()));
    std::sort(order.begin(), order.end());
    joints = order;
  }
  const std::string torque = "figures/gap_torque_" + traj + ".svg";
  io::write_file_atomically(dir / torque, torque_figure(*vb, *va, joints, c, options));
  files.push_back(dir / torque);
  md += fmt::format("## {}: torques and errors\n\nMeasured (black), {} (grey, dashed) and {} (red).\n\n![{}]({})\n",
                    traj, bl, al, traj, torque);

  // The disagreement localized (joint, regime, frequency, lag), before and after.
  md += "\n" + localization_section(before, c, bl, "before", dir, files);
  md += localization_section(after, c, al, "after", dir, files);

  io::write_file_atomically(dir / "gap.md", md);
  files.push_back(dir / "gap.md");
  return files;
}

}  // namespace symoro::diagnose
