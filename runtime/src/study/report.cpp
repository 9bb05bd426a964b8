#include "symoro/study/report.hpp"

#include "symoro/study/acceptance.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "report_tables.hpp"
#include "symoro/study/reproduction.hpp"
#include "symoro/report/svg_plot.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/study/prediction_band.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_text.hpp"

namespace symoro::study {

namespace {

using namespace report_detail;

constexpr double deg_per_rad = 180 / 3.14159265358979323846;

// One colour and marker per sampling interval, in ascending order of the interval.
constexpr const char* palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"};
constexpr svg::Marker markers[] = {svg::Marker::circle, svg::Marker::square, svg::Marker::triangle,
                                   svg::Marker::diamond, svg::Marker::cross};

svg::Style interval_style(std::size_t k) {
  svg::Style s;
  s.colour = palette[k % std::size(palette)];
  s.marker = markers[k % std::size(markers)];
  return s;
}

std::string degrees(const Eigen::VectorXd& pose) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < pose.size(); ++i) out += (i ? ", " : "") + fixed(pose(i) * deg_per_rad, 1);
  return out + "]";
}

// A trajectory's name as a file-name part: letters, digits, '-' and '_' only.
std::string file_part(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return out.empty() ? "unnamed" : out;
}

// --- Figures -------------------------------------------------------------------------------

std::string routing_figure(const StudyResult& study) {
  svg::Panel p;
  p.title = "Routing before CLIE";
  p.x_label = "sampling interval";
  p.y_label = "runs";
  svg::Series oc, osc;
  oc.name = "PD-OLS → CLIE";
  osc.name = "NPD-OLS → SDP → CLIE";
  oc.style.colour = "#2ca02c";
  osc.style.colour = "#d62728";
  for (double t : intervals(study)) {
    p.categories.push_back(fmt::format("{} ms", interval_ms(t)));
    int n_oc = 0, n_osc = 0;
    for (const auto& r : study.runs)
      if (interval_ms(r.interval) == interval_ms(t)) n_oc += is_o_c(r), n_osc += is_o_s_c(r);
    oc.y.push_back(n_oc);
    osc.y.push_back(n_osc);
  }
  p.bars = {oc, osc};
  svg::Figure f;
  f.panels = {p};
  f.panel_width = 420;
  return svg::render(f);
}

bool pca_fits(const StudyResult& study) {
  const auto rows = static_cast<Eigen::Index>(study.runs.size());
  const auto& c = study.pca;
  return rows > 0 && c.ols.rows() == rows && c.sdp.rows() == rows && c.clie.rows() == rows && c.ols.cols() >= 1 &&
         c.sdp.cols() == c.ols.cols() && c.clie.cols() == c.ols.cols();
}

// PC1 vs PC2 of the three stages on shared axes (the contraction is the point of the figure):
// colour and marker by interval, the representative ringed, the example trajectories labelled.
std::string pca_figure(const StudyResult& study, const ReportOptions& options) {
  const auto& c = study.pca;
  const bool two = c.ols.cols() >= 2;
  auto x_of = [](const Eigen::MatrixXd& s, int i) { return s(i, 0); };
  auto y_of = [two](const Eigen::MatrixXd& s, int i) { return two ? s(i, 1) : 0.0; };
  svg::Range xr{INFINITY, -INFINITY}, yr{INFINITY, -INFINITY};
  for (const Eigen::MatrixXd* s : {&c.ols, &c.sdp, &c.clie})
    for (int i = 0; i < s->rows(); ++i)
      if (std::isfinite(x_of(*s, i)) && std::isfinite(y_of(*s, i))) {
        xr = {std::min(xr.lo, x_of(*s, i)), std::max(xr.hi, x_of(*s, i))};
        yr = {std::min(yr.lo, y_of(*s, i)), std::max(yr.hi, y_of(*s, i))};
      }
  const bool any = xr.lo <= xr.hi;
  auto padded = [](svg::Range r) {
    const double pad = 0.05 * (r.hi - r.lo);
    return svg::Range{r.lo - pad, r.hi + pad};
  };
  const auto all_intervals = intervals(study);
  const auto explained = [&](int k) {
    return c.explained.size() > k ? fmt::format(" ({:.1f} %)", 100 * c.explained(k)) : std::string();
  };
  svg::Figure f;
  f.title = "Parameter clouds in a common PCA basis";
  const char* titles[] = {"OLS", "SDP", "CLIE"};
  const Eigen::MatrixXd* stages[] = {&c.ols, &c.sdp, &c.clie};
  for (int s = 0; s < 3; ++s) {
    svg::Panel p;
    p.title = titles[s];
    p.x_label = "PC1" + explained(0);
    p.y_label = two ? "PC2" + explained(1) : "";
    if (any) {
      p.x_range = padded(xr);
      p.y_range = padded(yr);
    }
    for (std::size_t k = 0; k < all_intervals.size(); ++k) {
      svg::Series series;
      series.name = fmt::format("{} ms", interval_ms(all_intervals[k]));
      series.style = interval_style(k);
      for (int i = 0; i < static_cast<int>(study.runs.size()); ++i)
        if (interval_ms(study.runs[i].interval) == interval_ms(all_intervals[k])) {
          series.x.push_back(x_of(*stages[s], i));
          series.y.push_back(y_of(*stages[s], i));
        }
      p.points.push_back(series);
    }
    for (int i = 0; i < static_cast<int>(study.runs.size()); ++i) {
      const auto& run = study.runs[i];
      const bool selected = i == study.selection.run;
      const bool example =
          std::find(options.examples.begin(), options.examples.end(), run.trajectory) != options.examples.end();
      if (!selected && !example) continue;
      svg::PointLabel l;
      l.x = x_of(*stages[s], i);
      l.y = y_of(*stages[s], i);
      l.text = run.id();
      l.ring = selected;
      l.colour = selected ? "#000000" : "#555555";
      p.labels.push_back(l);
    }
    f.panels.push_back(p);
  }
  return svg::render(f);
}

const ValidationRecord* find_validation(const StudyResult& study, const std::string& trajectory) {
  for (const auto& v : study.validation)
    if (v.trajectory == trajectory) return &v;
  return nullptr;
}

// Measured vs simulated torque of the chosen joints, stacked; nothing when the record has no
// series for them.
std::string validation_figure(const ValidationRecord& v, const std::vector<int>& joints) {
  const auto n = v.time.size();
  svg::Figure f;
  f.title = v.trajectory + ": measured and simulated joint torque";
  f.columns = 1;
  f.panel_width = 760;
  f.panel_height = 210;
  auto series = [&](const Eigen::MatrixXd& tau, int j, const char* name, const char* colour, double width,
                    const char* dash) {
    svg::Series s;
    s.name = name;
    s.style.colour = colour;
    s.style.width = width;
    s.style.dash = dash;
    s.x.assign(v.time.data(), v.time.data() + n);
    for (Eigen::Index i = 0; i < n; ++i) s.y.push_back(tau(i, j));
    return s;
  };
  for (int j : joints) {
    if (j < 0 || v.tau_measured.rows() != n || j >= v.tau_measured.cols() || n < 2) continue;
    svg::Panel p;
    p.title = fmt::format("J{}", j + 1);
    p.y_label = "τ [N m]";
    p.x_label = "t [s]";
    p.lines.push_back(series(v.tau_measured, j, "measured", "#000000", 1.6, ""));
    if (v.tau_clie.rows() == n && j < v.tau_clie.cols())
      p.lines.push_back(series(v.tau_clie, j, "CLIE", "#1f77b4", 1.3, "6 3"));
    if (v.tau_rescue.rows() == n && j < v.tau_rescue.cols())
      p.lines.push_back(series(v.tau_rescue, j, "PD-rescue", "#d62728", 1.1, ""));
    // The 95 % prediction band around the accepted torque (prediction_band.hpp).
    if (v.tau_rescue.rows() == n && v.tau_band.rows() == n && j < v.tau_band.cols()) {
      p.lines.push_back(series(v.tau_rescue + v.tau_band, j, "95 % band", "#f4a6a6", 0.7, "2 2"));
      p.lines.push_back(series(v.tau_rescue - v.tau_band, j, "", "#f4a6a6", 0.7, "2 2"));
    }
    f.panels.push_back(p);
  }
  return f.panels.empty() ? std::string() : svg::render(f);
}

// --- Markdown ------------------------------------------------------------------------------

std::string summary(const StudyResult& study) {
  std::string out = "## Summary\n\n";
  const RunRecord* sel = selected_run(study);
  if (sel) {
    out += fmt::format(
        "- **Accepted model**: {}, {}; final all-pose audit{} λ_min = {} at the worst pose {} deg: {}.\n", sel->id(),
        study.rescued
            ? (study.rescue_feasible
                   ? (study.consistency == "physical"
                          ? fmt::format("rescued onto the physically consistent set (clearance {} of each link's size)",
                                        sig(study.rescue_eps, 3))
                          : fmt::format("PD-rescued (ε = {})", sig(study.rescue_eps, 3)))
                   : "the rescue's projection FAILED (" + study.rescue_status + ")")
            : std::string("the run's final vector as is (no rescue needed)"),
        study.final_audit.empty() ? "" : " (" + study.final_audit + ")", sig(study.final_lambda_min, 4),
        degrees(study.final_worst_pose),
        study.accepted ? "**accepted**"
                       : fmt::format("**not accepted** ({})", fmt::join(acceptance_verdict(study).reasons, "; ")));
    out += fmt::format("- **Physical consistency** of the accepted vector ({} path): {}.\n",
                       study.consistency == "physical" ? "the physical" : "the paper's PD",
                       study.final_consistency_note.empty() ? std::string("not checked")
                       : study.final_consistent
                           ? fmt::format("a consistent set of link inertials maps onto it ({}): `dynid export --urdf` "
                                         "reproduces it exactly",
                                         study.final_consistency_note)
                           : study.final_consistency_note);
    out +=
        fmt::format("- **Selection**: {}{}.\n", study.selection.rule.empty() ? "by centrality" : study.selection.rule,
                    study.selection.components > 0 ? fmt::format(" ({} PCA components)", study.selection.components)
                                                   : std::string());
  } else {
    out += fmt::format("- **Accepted model**: none; no representative was selected ({}).\n",
                       study.selection.rule.empty() ? "no run produced a final vector" : study.selection.rule);
  }
  if (!study.stages.empty()) {
    out += "- **Stages**:\n";
    for (const auto& line : study.stages) out += "  - " + line + "\n";
  }
  if (!study.validation.empty()) {
    double sums[4] = {0, 0, 0, 0};
    std::string names;
    for (const auto& v : study.validation) {
      sums[0] += v.rmse_clie, sums[1] += v.rmse_rescue, sums[2] += v.mne_clie, sums[3] += v.mne_rescue;
      names += (names.empty() ? "" : ", ") + v.trajectory;
    }
    const double n = static_cast<double>(study.validation.size());
    std::string kinds;
    for (const auto& v : study.validation)
      if (kinds.find(v.kind) == std::string::npos) kinds += (kinds.empty() ? "" : " and ") + v.kind;
    out +=
        fmt::format("- **Validation** ({}; mean over {}): RMSE {} N m (final) / {} N m (accepted); MNE {} / {}.\n",
                    kinds, names, sig(sums[0] / n, 5), sig(sums[1] / n, 5), sig(sums[2] / n, 5), sig(sums[3] / n, 5));
    for (const auto& v : study.validation)
      if (!v.note.empty()) out += fmt::format("  - {}: {}\n", v.trajectory, v.note);
  } else {
    out += "- **Validation**: no held-out records.\n";
  }
  std::vector<std::string> trajectories, failed;
  int converged = 0, pd = 0;
  double t[4] = {0, 0, 0, 0};
  for (const auto& r : study.runs) {
    if (std::find(trajectories.begin(), trajectories.end(), r.trajectory) == trajectories.end())
      trajectories.push_back(r.trajectory);
    converged += r.clie_success;
    pd += r.clie_ran && r.clie_pd;
    if (r.clie_ran && !r.clie_success) failed.push_back(r.id());
    t[0] += r.t_ols, t[1] += r.t_audit, t[2] += r.t_sdp, t[3] += r.t_clie;
  }
  std::string ms;
  for (double i : intervals(study)) ms += (ms.empty() ? "" : ", ") + std::to_string(interval_ms(i));
  out +=
      fmt::format("- **Runs**: {} ({} trajectories × intervals {} ms); CLIE converged in {}, PD after CLIE in {}{}.\n",
                  study.runs.size(), trajectories.size(), ms.empty() ? "none" : ms, converged, pd,
                  failed.empty() ? std::string() : fmt::format("; CLIE failed for {}", fmt::join(failed, ", ")));
  int checked = 0, ols_pd = 0, ols_consistent = 0, final_pd = 0, final_consistent = 0;
  for (const auto& r : study.runs) {
    if (r.failed || !r.physical) continue;
    ++checked;
    ols_pd += r.ols_pd, ols_consistent += r.ols_consistent;
    final_pd += r.phi_clie.size() > 0 && r.clie_pd, final_consistent += r.phi_clie.size() > 0 && r.clie_consistent;
  }
  if (checked > 0)
    out += fmt::format(
        "- **Physical consistency of the runs** (a consistent set of link inertials maps onto the vector; "
        "all-pose PD is necessary, not sufficient): OLS {} of {} (PD {}), final vectors {} (PD {}).\n",
        ols_consistent, checked, ols_pd, final_consistent, final_pd);
  out += fmt::format(
      "- **Wall time**: {} s for this invocation on {}{} thread{}; run stages sum to {} s "
      "(OLS {}, audit {}, SDP {}, CLIE {}){}.\n\n",
      fixed(study.wall, 1), study.ranks > 1 ? fmt::format("{} MPI ranks x ", study.ranks) : "", study.threads,
      study.threads == 1 ? "" : "s", fixed(study.wall_runs, 1), fixed(t[0], 1), fixed(t[1], 1), fixed(t[2], 1),
      fixed(t[3], 1),
      study.worker_peak_mb > 0 ? fmt::format("; peak memory of a trajectory's process {} MB ({})",
                                             fixed(study.worker_peak_mb, 0), study.worker_peak_trajectory)
                               : "");
  return out;
}

// The paper's findings next to this study's, each computed (reproduction.hpp).
std::string reproduction_section(const StudyResult& study) {
  std::string out = "## Reproduction of the paper's findings\n\n";
  MarkdownTable table({"Finding", "Paper (CRANE-X7, real arm)", "This study", "Verdict", "Note"});
  for (const Finding& f : paper_findings(study)) table.row({f.name, f.paper, f.study, f.verdict, f.note});
  out += table.str();
  out +=
      "\ntr Σ_z: the trace of the sample covariance of the standardized parameters (the cloud figure's "
      "standardization; smaller is tighter). The paper's values are from its tables; this study's are computed from "
      "its run records; the clouds are drawn under Parameter clouds. docs/identification.md explains the findings "
      "that differ.\n\n";
  return out;
}

std::string clouds_section(const StudyResult& study, bool figure) {
  std::string out = "## Parameter clouds\n\n";
  if (figure)
    out += "![Parameter clouds of OLS, SDP and CLIE in a common PCA basis](figures/pca_clouds.svg)\n\n";
  else
    out += "No PCA scores for the runs; the cloud figure is left out.\n\n";
  if (study.pca.explained.size() > 0) {
    std::string parts;
    for (Eigen::Index k = 0; k < std::min<Eigen::Index>(study.pca.explained.size(), 5); ++k)
      parts += (k ? ", " : "") + fmt::format("PC{} {:.1f} %", k + 1, 100 * study.pca.explained(k));
    out += "Explained variance: " + parts + ".\n\n";
  }
  return out + dispersion_table(study) + central_runs_table(study);
}

// --- Parameter files -----------------------------------------------------------------------

// The accepted vector, checked against the names (an empty one writes an empty list).
const Eigen::VectorXd& accepted_vector(const StudyResult& study) {
  const auto np = static_cast<Eigen::Index>(study.names.size());
  if (study.phi_rescue.size() != 0 && !study.names.empty() && study.phi_rescue.size() != np)
    throw std::invalid_argument(
        fmt::format("the accepted parameter vector has {} entries for {} names", study.phi_rescue.size(), np));
  return study.phi_rescue;
}

using io::yaml_number;
using io::yaml_quoted;

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

void write_parameters_yaml(const StudyResult& study, const std::filesystem::path& file) {
  const Eigen::VectorXd& phi = accepted_vector(study);
  const RunRecord* sel = selected_run(study);
  std::string y = "# Accepted dynamic parameters (symoro identification study); values round-trip exactly.\n";
  y += "robot: " + yaml_quoted(study.robot) + "\n";
  y += "model: " + yaml_quoted(study.model) + "\n";
  y += "data_source: " + yaml_quoted(study.data_source) + "\n";
  y += "source_run: " + (sel ? yaml_quoted(sel->id()) : std::string("null")) + "\n";
  y += fmt::format("rescued: {}\n", study.rescued);
  y += "rescue_eps: " + yaml_number(study.rescue_eps) + "\n";
  y += "final_lambda_min: " + yaml_number(study.final_lambda_min) + "\n";
  y += "final_worst_pose_deg: [";
  for (Eigen::Index i = 0; i < study.final_worst_pose.size(); ++i)
    y += (i ? ", " : "") + yaml_number(study.final_worst_pose(i) * deg_per_rad);
  y += "]\n";
  y += fmt::format("accepted: {}\n", study.accepted);
  y += "consistency: " + yaml_quoted(study.consistency) + "\n";
  y += fmt::format("physically_consistent: {}\n", study.final_consistent);
  // The timing the values carry (an arm's rotor inertias take the logged torque's lead): dynid
  // payload and predict default to it.
  y += "torque_delay_ms: " + yaml_number(study.torque_delay * 1000) + "\n";
  // What dynid control checks before it drives an arm with these values: an edit breaks it.
  std::vector<std::string> names;
  for (Eigen::Index i = 0; i < phi.size(); ++i) names.push_back(name_of(study, static_cast<int>(i)));
  y += "digest: " + io::parameters_digest(study.robot, study.model, study.accepted, names, phi) + "\n";
  y += phi.size() == 0 ? "parameters: []\n" : "parameters:\n";
  for (Eigen::Index i = 0; i < phi.size(); ++i)
    y += fmt::format("  - {{name: {}, unit: {}, value: {}}}\n", yaml_quoted(name_of(study, static_cast<int>(i))),
                     yaml_quoted(unit_of(study, static_cast<int>(i))), yaml_number(phi(i)));
  io::write_file_atomically(file, y);
}

void write_parameters_csv(const StudyResult& study, const std::filesystem::path& file) {
  const Eigen::VectorXd& phi = accepted_vector(study);
  const RunRecord* sel = selected_run(study);
  auto column = [&](const Eigen::VectorXd& v, Eigen::Index i) {
    return v.size() == phi.size() ? io::number_text(v(i)) : std::string();
  };
  std::string csv = sel ? "name,unit,value,ols,sdp,clie\n" : "name,unit,value\n";
  for (Eigen::Index i = 0; i < phi.size(); ++i) {
    csv += csv_field(name_of(study, static_cast<int>(i))) + "," + csv_field(unit_of(study, static_cast<int>(i))) + "," +
           io::number_text(phi(i));
    if (sel) csv += "," + column(sel->phi_ols, i) + "," + column(sel->phi_sdp, i) + "," + column(sel->phi_clie, i);
    csv += "\n";
  }
  io::write_file_atomically(file, csv);
}

std::vector<std::filesystem::path> write_report(const StudyResult& study, const std::filesystem::path& dir,
                                                const ReportOptions& options) {
  accepted_vector(study);  // a mismatch throws before anything is written
  const auto figures = dir / "figures";
  std::filesystem::create_directories(figures);
  std::vector<std::filesystem::path> written;
  auto put = [&](const std::filesystem::path& file, const std::string& content) {
    io::write_file_atomically(file, content);
    written.push_back(file);
  };

  // Figures first: the Markdown embeds only those that exist.
  const bool routing = !study.runs.empty();
  if (routing) put(figures / "routing.svg", routing_figure(study));
  const bool clouds = pca_fits(study);
  if (clouds) put(figures / "pca_clouds.svg", pca_figure(study, options));
  std::string torque_file;
  if (const ValidationRecord* v = find_validation(study, options.validation_figure)) {
    const std::string svg = validation_figure(*v, options.figure_joints);
    if (!svg.empty()) {
      torque_file = "validation_" + file_part(v->trajectory) + ".svg";
      put(figures / torque_file, svg);
    }
  }

  std::string md = fmt::format("# Identification report: {} ({})\n\n", study.robot.empty() ? "robot" : study.robot,
                               study.model.empty() ? "model" : study.model);
  if (!study.data_source.empty()) md += "Data source: " + study.data_source + "\n\n";
  md += summary(study);
  md += reproduction_section(study);
  md += excitation_section(study);
  md += routing_table(study);
  if (routing) md += "![Routing per sampling interval](figures/routing.svg)\n\n";
  md += route_examples_table(study, options);
  md += clouds_section(study, clouds);
  md += transition_table(study);
  md += rescue_delta_table(study);
  md += moves_table(study);
  md += validation_table(study);
  if (!torque_file.empty())
    md += fmt::format("![{} torques: measured, CLIE and PD-rescue{}](figures/{})\n\n", options.validation_figure,
                      study.uncertainty.covariance.size() > 0
                          ? ", with the open-loop 95 % prediction band dashed around the PD-rescue (a guide where "
                            "the simulation is closed-loop)"
                          : "",
                      torque_file);
  else if (!study.validation.empty())
    md += fmt::format("No torque series for {}; its figure is left out.\n\n", options.validation_figure);
  md += appendix_record(study);
  md += parameter_table(study);
  put(dir / "report.md", md);

  write_parameters_yaml(study, dir / "parameters.yaml");
  written.push_back(dir / "parameters.yaml");
  write_parameters_csv(study, dir / "parameters.csv");
  written.push_back(dir / "parameters.csv");
  if (study.uncertainty.covariance.size() > 0)
    put(dir / "uncertainty.yaml", uncertainty_yaml(study.uncertainty, study.robot));
  return written;
}

}  // namespace symoro::study
