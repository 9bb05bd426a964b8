#include "report_tables.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include <fmt/format.h>

#include "symoro/detail/numbers.hpp"
#include "pca.hpp"

namespace symoro::study::report_detail {

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

namespace {

using symoro::detail::nan;

int parameter_count(const StudyResult& study) {
  if (!study.names.empty()) return static_cast<int>(study.names.size());
  if (study.phi_rescue.size() > 0) return static_cast<int>(study.phi_rescue.size());
  for (const auto& r : study.runs)
    if (r.phi_ols.size() > 0) return static_cast<int>(r.phi_ols.size());
  return 0;
}

bool usable(const Eigen::VectorXd& phi, int np) { return np > 0 && phi.size() == np && phi.allFinite(); }

std::string value_or_dash(const Eigen::VectorXd& phi, int i, int np) {
  return phi.size() == np && np > 0 ? sig(phi(i), 6) : "--";
}

std::string eps_text(const RunRecord& r) {
  if (!is_o_s_c(r)) return "--";
  return sig(r.eps, 3) + (r.sdp_feasible ? "" : " (infeasible)");
}

std::string termination(const RunRecord& r) {
  return r.clie_termination.empty() ? std::string("no termination reported") : r.clie_termination;
}

std::string clie_status(const RunRecord& r) {
  if (!r.clie_ran) return termination(r);  // "not run: ..."
  if (r.clie_success) return fmt::format("ok, {} it", r.clie_iterations);
  return "failed: " + termination(r);
}

std::string cost_reduction(const RunRecord& r) {
  if (!(r.clie_cost_initial > 0) || !std::isfinite(r.clie_cost_final)) return "n/a";
  return fixed(100 * (1 - r.clie_cost_final / r.clie_cost_initial), 1) + " %";
}

}  // namespace

// --- Text ---------------------------------------------------------------------------------

std::string fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  return fmt::format("{:.{}f}", value, decimals);
}

std::string sig(double value, int digits) {
  if (!std::isfinite(value)) return "n/a";
  return fmt::format("{:.{}g}", value, digits);
}

std::string yes_no(bool value) { return value ? "yes" : "no"; }

long interval_ms(double interval) { return std::lround(interval * 1000); }

// --- Views --------------------------------------------------------------------------------

std::vector<double> intervals(const StudyResult& study) {
  std::vector<double> all;
  for (const auto& r : study.runs)
    if (std::none_of(all.begin(), all.end(), [&](double t) { return interval_ms(t) == interval_ms(r.interval); }))
      all.push_back(r.interval);
  std::sort(all.begin(), all.end());
  return all;
}

const RunRecord* find_run(const StudyResult& study, const std::string& trajectory, double interval) {
  for (const auto& r : study.runs)
    if (r.trajectory == trajectory && interval_ms(r.interval) == interval_ms(interval)) return &r;
  return nullptr;
}

const RunRecord* selected_run(const StudyResult& study) {
  const int i = study.selection.run;
  return i >= 0 && i < static_cast<int>(study.runs.size()) ? &study.runs[i] : nullptr;
}

std::string family(const std::string& trajectory) {
  std::size_t n = 0;
  while (n < trajectory.size() && std::isalpha(static_cast<unsigned char>(trajectory[n]))) ++n;
  return n == 0 ? std::string("other") : trajectory.substr(0, n);
}

bool is_o_c(const RunRecord& run) { return run.route == "O-C"; }
bool is_o_s_c(const RunRecord& run) { return run.route == "O-S-C"; }

std::string unit_of(const StudyResult& study, int i) {
  return i < static_cast<int>(study.units.size()) ? study.units[i] : std::string();
}

std::string name_of(const StudyResult& study, int i) {
  return i < static_cast<int>(study.names.size()) ? study.names[i] : fmt::format("p{}", i + 1);
}

std::vector<Dispersion> dispersion_by_interval(const StudyResult& study) {
  const int np = parameter_count(study);
  std::vector<Dispersion> out;
  if (np == 0) return out;
  auto stage = [](const RunRecord& r, int s) -> const Eigen::VectorXd& {
    return s == 0 ? r.phi_ols : s == 1 ? r.phi_sdp : r.phi_clie;
  };
  // The PCA's standardization when it fits, else the pooled one (what the PCA would use).
  PcaClouds basis;
  basis.mean = study.pca.mean;
  basis.scale = study.pca.scale;
  if (basis.mean.size() != np || basis.scale.size() != np) {
    std::vector<Eigen::VectorXd> pooled;
    for (const auto& r : study.runs)
      for (int s = 0; s < 3; ++s)
        if (usable(stage(r, s), np)) pooled.push_back(stage(r, s));
    const double n = static_cast<double>(pooled.size());
    basis.mean = Eigen::VectorXd::Zero(np);
    for (const auto& v : pooled) basis.mean += v / n;
    basis.scale = Eigen::VectorXd::Zero(np);
    for (const auto& v : pooled) basis.scale += (v - basis.mean).array().square().matrix() / std::max(1.0, n - 1);
    basis.scale = basis.scale.cwiseSqrt();
  }
  for (int i = 0; i < np; ++i)
    if (!(std::abs(basis.scale(i)) > 0)) basis.scale(i) = 1;  // a constant parameter carries no spread

  auto dispersion_at = [&](double interval, bool all) {
    Dispersion d;
    d.interval = all ? nan : interval;
    for (int s = 0; s < 3; ++s) {
      std::vector<Eigen::VectorXd> cloud;
      for (const auto& r : study.runs)
        if ((all || interval_ms(r.interval) == interval_ms(interval)) && usable(stage(r, s), np))
          cloud.push_back(stage(r, s));
      d.count[s] = static_cast<int>(cloud.size());
      d.trace[s] = cloud.size() < 2 ? nan : cloud_dispersion(cloud, basis);
    }
    return d;
  };
  for (double t : intervals(study)) out.push_back(dispersion_at(t, false));
  out.push_back(dispersion_at(0, true));
  return out;
}

// --- Sections -----------------------------------------------------------------------------

std::string routing_table(const StudyResult& study) {
  std::string out = "## Table III: routing summary before CLIE\n\n";
  if (study.runs.empty()) return out + "No runs.\n\n";
  const bool any_other =
      std::any_of(study.runs.begin(), study.runs.end(), [](const RunRecord& r) { return !is_o_c(r) && !is_o_s_c(r); });
  std::vector<std::string> header{"T_s [ms]", "PD-OLS → CLIE", "NPD-OLS → SDP → CLIE"};
  if (any_other) header.push_back("Other route");
  for (const char* h : {"Total", "SDP infeasible", "CLIE converged", "CLIE PD"}) header.push_back(h);
  MarkdownTable table(header);
  auto add = [&](const std::string& label, bool all, double interval) {
    int oc = 0, osc = 0, other = 0, total = 0, infeasible = 0, converged = 0, pd = 0;
    for (const auto& r : study.runs) {
      if (!all && interval_ms(r.interval) != interval_ms(interval)) continue;
      ++total;
      if (is_o_c(r))
        ++oc;
      else if (is_o_s_c(r))
        ++osc;
      else
        ++other;
      if (is_o_s_c(r) && !r.sdp_feasible) ++infeasible;
      if (r.clie_success) ++converged;
      if (r.clie_ran && r.clie_pd) ++pd;
    }
    std::vector<std::string> row{label, std::to_string(oc), std::to_string(osc)};
    if (any_other) row.push_back(std::to_string(other));
    for (int v : {total, infeasible, converged, pd}) row.push_back(std::to_string(v));
    table.row(row);
  };
  for (double t : intervals(study)) add(std::to_string(interval_ms(t)), false, t);
  add("All", true, 0);
  return out + table.str() + "\n";
}

std::string route_examples_table(const StudyResult& study, const ReportOptions& options) {
  std::string out = "## Table IV: route examples\n\n";
  // The paper's example trajectories where this study has them (a robot's own logs have other
  // names), and the selected one.
  std::vector<std::string> shown;
  for (const auto& t : options.examples)
    if (std::find(shown.begin(), shown.end(), t) == shown.end() &&
        std::any_of(study.runs.begin(), study.runs.end(), [&](const RunRecord& r) { return r.trajectory == t; }))
      shown.push_back(t);
  if (const RunRecord* sel = selected_run(study))
    if (std::find(shown.begin(), shown.end(), sel->trajectory) == shown.end()) shown.push_back(sel->trajectory);
  if (shown.empty() || study.runs.empty()) return out + "No trajectories to compare.\n\n";
  std::vector<std::string> header{"T_s [ms]"};
  for (const auto& t : shown)
    for (const char* h : {" κ", " route", " ε_PD"}) header.push_back(t + h);
  MarkdownTable table(header);
  for (double interval : intervals(study)) {
    std::vector<std::string> row{std::to_string(interval_ms(interval))};
    for (const auto& t : shown) {
      const RunRecord* r = find_run(study, t, interval);
      if (!r) {
        row.insert(row.end(), {"n/a", "n/a", "n/a"});
        continue;
      }
      row.insert(row.end(), {fixed(r->kappa, 1), r->route.empty() ? "n/a" : r->route, eps_text(*r)});
    }
    table.row(row);
  }
  return out + table.str() +
         "\nO-C: OLS → CLIE (the OLS estimate passed the all-pose audit); O-S-C: OLS → SDP → CLIE. "
         "A dash in ε_PD: the SDP projection was skipped.\n\n";
}

std::string transition_table(const StudyResult& study) {
  const RunRecord* r = selected_run(study);
  if (!r) return "## Table V: stage-wise evolution of the representative\n\nNo representative was selected.\n\n";
  std::string out = fmt::format("## Table V: stage-wise evolution of the representative {}\n\n", r->id());
  MarkdownTable table({"Stage", "PD", "Route", "ε_PD", "λ_min", "Remark"});
  table.row(
      {"OLS", yes_no(r->ols_pd), "--", "--", sig(r->ols_lambda_min, 4),
       fmt::format("Initial estimate, κ = {}, residual RMS {} N m", fixed(r->kappa, 1), sig(r->residual_rms, 4))});
  std::string sdp_remark = is_o_c(*r)        ? "Skipped: the OLS estimate was already PD"
                           : r->sdp_feasible ? "Feasible projection before CLIE"
                                             : "No margin gave a PD projection; CLIE started from the last";
  table.row({"SDP", is_o_s_c(*r) ? yes_no(r->sdp_feasible) : "--", r->route.empty() ? "n/a" : r->route, eps_text(*r),
             "--", sdp_remark});
  std::string clie_remark = !r->clie_ran ? "CLIE " + termination(*r) + "; the SDP (or PD OLS) vector is the final one"
                            : r->clie_success ? fmt::format("Converged ({} iterations, cost {} lower)",
                                                            r->clie_iterations, cost_reduction(*r))
                                              : "CLIE failed: " + termination(*r);
  if (r->clie_success && !r->clie_pd) clie_remark += "; statistically central but non-PD";
  table.row({"CLIE", yes_no(r->clie_pd), "--", "--", sig(r->clie_lambda_min, 4), clie_remark});
  const bool physical = study.consistency == "physical";
  std::string final_remark =
      study.rescued
          ? (study.accepted
                 ? (physical ? "Projected onto the physically consistent set; final accepted model"
                             : "Final accepted model")
                 : (physical ? "Rescued, but the final checks failed" : "Rescued, but the final audit failed"))
          : (study.accepted
                 ? (physical ? "Not needed: the CLIE candidate has a consistent set and is accepted as is"
                             : "Not needed: the CLIE candidate was PD and is accepted as is")
                 : (physical ? "Not rescued; the final checks failed" : "Not rescued; the final audit failed"));
  table.row({physical ? "Physical rescue" : "PD-rescue", yes_no(study.accepted), "--",
             study.rescued ? sig(study.rescue_eps, 3) : "--", sig(study.final_lambda_min, 4), final_remark});
  return out + table.str() + "\nλ_min: smallest eigenvalue of M(θ; φ) found by the all-pose audit.\n\n";
}

std::string rescue_delta_table(const StudyResult& study, int count) {
  const RunRecord* r = selected_run(study);
  const std::string rescue = study.consistency == "physical" ? "physical rescue" : "PD-rescue";
  std::string out = "## Table VI: largest parameter changes, CLIE → " + rescue;
  out += r ? fmt::format(" ({})\n\n", r->id()) : "\n\n";
  const int np = parameter_count(study);
  if (!r || r->phi_clie.size() != np || study.phi_rescue.size() != np || np == 0)
    return out + "No CLIE and rescued parameter vectors to compare.\n\n";
  if (!study.rescued)
    return out + (study.consistency == "physical"
                      ? "The CLIE candidate passed the final checks and was accepted unchanged: no rescue.\n\n"
                      : "The CLIE candidate passed the final audit and was accepted unchanged: no rescue.\n\n");
  std::vector<int> order(np);
  std::iota(order.begin(), order.end(), 0);
  const Eigen::VectorXd delta = study.phi_rescue - r->phi_clie;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(delta(a)) > std::abs(delta(b)); });
  MarkdownTable table({"Parameter", "Unit", "CLIE", study.consistency == "physical" ? "Physical rescue" : "PD-rescue",
                       "Δ = rescue − CLIE"});
  for (int k = 0; k < std::min(count, np); ++k) {
    const int i = order[k];
    table.row(
        {name_of(study, i), unit_of(study, i), sig(r->phi_clie(i), 6), sig(study.phi_rescue(i), 6), sig(delta(i), 4)});
  }
  return out + table.str() +
         fmt::format("\n‖Δ‖₂ = {}, ‖Δ‖₂ / ‖φ_CLIE‖₂ = {}.\n\n", sig(delta.norm(), 4),
                     sig(delta.norm() / r->phi_clie.norm(), 4));
}

// Against the raw measured torque (raw_torque.hpp), when the records carry it.
std::string raw_validation_table(const StudyResult& study) {
  std::string filter;
  for (const auto& v : study.validation)
    if (std::isfinite(v.raw_rmse_rescue)) filter = v.raw_filter;
  if (filter.empty()) return "";
  MarkdownTable table({"Trajectory", "Final RMSE [N m]", "Accepted RMSE [N m]",
                       "Accepted, mean of the joints' RMSE [N m]", "Accepted, per joint [N m]",
                       "The torque's own content above the cutoff, per joint (mean) [N m]"});
  for (const auto& v : study.validation) {
    if (!std::isfinite(v.raw_rmse_rescue)) continue;
    std::string joints, floor;
    for (Eigen::Index j = 0; j < v.raw_rmse_joint_rescue.size(); ++j)
      joints += (j ? ", " : "") + sig(v.raw_rmse_joint_rescue(j), 3);
    for (Eigen::Index j = 0; j < v.raw_floor_joint.size(); ++j) floor += (j ? ", " : "") + sig(v.raw_floor_joint(j), 3);
    if (v.raw_floor_joint.size() > 0) floor += " (" + sig(v.raw_floor_joint.mean(), 4) + ")";
    const double mean = v.raw_rmse_joint_rescue.size() > 0 ? v.raw_rmse_joint_rescue.mean() : std::nan("");
    table.row({v.trajectory, sig(v.raw_rmse_clie, 6), sig(v.raw_rmse_rescue, 6), sig(mean, 6), joints,
               floor.empty() ? "-" : floor});
  }
  return "\nAgainst the raw measured torque, open loop at the log's own rate: " + filter +
         ". RMSE: over all joints and samples together, sqrt(sum e^2 / (samples x joints)); mean of the joints' RMSE: "
         "the "
         "average over joints of sqrt(sum_k e_j(k)^2 / samples) (docs/identification.md, \"Validation against the raw "
         "torque\", rescores it with NumPy). The last column is the raw torque minus its own zero-phase low-pass at "
         "the "
         "cutoff, on the same samples: a model of the low-passed motion follows next to none of it, so it is the "
         "floor of these errors on this log (sensor noise and dynamics beyond the band).\n\n" +
         table.str() + "\n";
}

// How often held-out torque falls inside the accepted vector's 95 % prediction band, if banded.
std::string band_validation_table(const StudyResult& study) {
  bool any = false;
  for (const auto& v : study.validation) any = any || std::isfinite(v.band_coverage);
  if (!any) return "";
  MarkdownTable table({"Trajectory", "Inside the 95 % band", "Per joint"});
  for (const auto& v : study.validation) {
    if (!std::isfinite(v.band_coverage)) continue;
    std::string joints;
    for (Eigen::Index j = 0; j < v.band_coverage_joint.size(); ++j)
      joints += fmt::format("{}{:.1f} %", j ? ", " : "", 100 * v.band_coverage_joint(j));
    table.row({v.trajectory, fmt::format("{:.1f} %", 100 * v.band_coverage), joints});
  }
  const PredictionUncertainty& u = study.uncertainty;
  std::string level;
  for (Eigen::Index j = 0; j < u.residual.size(); ++j) level += fmt::format("{}{:.3g}", j ? ", " : "", u.residual(j));
  return fmt::format(
             "\nPrediction bands, open loop: the accepted vector's torque +- 1.96 sqrt(w' C w + s_j^2), with C the "
             "parameters' covariance (Newey-West over {} lags) and s_j the residual's own level ({} N m), both on {} "
             "({} "
             "samples); report/uncertainty.yaml holds them. A calibrated band holds about 95 % of the held-out samples "
             "(docs/uncertainty.md).\n\n",
             u.lags, level, u.source, u.samples) +
         table.str() + "\n";
}

// Where the preprocessing left samples out at a moving log end (preprocess/edges.hpp), if anywhere.
std::string edge_note(const StudyResult& study) {
  std::string runs, held;
  for (const auto& r : study.runs)
    if (r.edge_samples > 0)
      runs += fmt::format("{}{} at {} ms: {}", runs.empty() ? "" : ", ", r.trajectory, interval_ms(r.interval),
                          r.edge_samples);
  for (const auto& v : study.validation)
    if (v.edge_samples > 0) held += fmt::format("{}{}: {}", held.empty() ? "" : ", ", v.trajectory, v.edge_samples);
  if (runs.empty() && held.empty()) return "";
  return "\nLeft out of fitting and scoring: the samples within the low-pass's settling time (6 time constants) of a "
         "log "
         "end where the arm moves, whose acceleration the filter's end padding gets wrong (docs/identification.md, "
         "\"The "
         "ends of a log\"). " +
         (runs.empty() ? std::string() : "Identification runs: " + runs + ". ") +
         (held.empty() ? std::string() : "Held out: " + held + ".") + "\n";
}

std::string validation_table(const StudyResult& study) {
  std::string out = "## Table VII: validation on held-out trajectories\n\n";
  if (study.validation.empty()) return out + "No validation records.\n\n";
  MarkdownTable table(
      {"Trajectory", "T_s [ms]", "Kind", "Final RMSE [N m]", "Accepted RMSE [N m]", "Final MNE", "Accepted MNE"});
  double sums[4] = {0, 0, 0, 0};
  for (const auto& v : study.validation) {
    const double values[4] = {v.rmse_clie, v.rmse_rescue, v.mne_clie, v.mne_rescue};
    std::vector<std::string> row{v.trajectory, std::to_string(interval_ms(v.interval)), v.kind};
    for (int k = 0; k < 4; ++k) {
      row.push_back(sig(values[k], 6));
      sums[k] += values[k];
    }
    table.row(row);
  }
  const double n = static_cast<double>(study.validation.size());
  table.row({"Mean", "", "", sig(sums[0] / n, 6), sig(sums[1] / n, 6), sig(sums[2] / n, 6), sig(sums[3] / n, 6)});
  out +=
      table.str() +
      "\nFinal: the representative run's last stage (CLIE, or SDP where CLIE did not run); accepted: after the rescue. "
      "Closed loop: the model under the experiment's controller; open loop: the model's inverse dynamics on the "
      "measured "
      "motion. RMSE over all joints and samples; MNE: mean over joints of ‖e_j‖ / ‖τ_m,j‖.\n\n";
  for (const auto& v : study.validation)
    if (!v.note.empty()) out += fmt::format("- {}: {}\n", v.trajectory, v.note);
  out += raw_validation_table(study);
  out += band_validation_table(study);
  out += edge_note(study);

  // Per joint, when the records carry it.
  int joints = 0;
  for (const auto& v : study.validation)
    joints = std::max(joints, static_cast<int>(std::max(v.rmse_joint_clie.size(), v.rmse_joint_rescue.size())));
  if (joints == 0) return out;
  std::vector<std::string> header{"Trajectory", "Model"};
  for (int j = 0; j < joints; ++j) header.push_back(fmt::format("J{}", j + 1));
  MarkdownTable per_joint(header);
  for (const auto& v : study.validation)
    for (const auto& [model, rmse] :
         {std::pair{"final RMSE [N m]", &v.rmse_joint_clie}, std::pair{"accepted RMSE [N m]", &v.rmse_joint_rescue},
          std::pair{"accepted NRMSE", &v.nrmse_joint_rescue}}) {
      if (rmse->size() == 0) continue;
      std::vector<std::string> row{v.trajectory, model};
      for (int j = 0; j < joints; ++j) row.push_back(j < rmse->size() ? sig((*rmse)(j), 4) : "--");
      per_joint.row(row);
    }
  return out + "Per joint (NRMSE: RMSE_j / rms(τ_m,j)):\n\n" + per_joint.str() + "\n";
}

std::string dispersion_table(const StudyResult& study) {
  std::string out = "### Cloud dispersion per interval\n\n";
  const auto all = dispersion_by_interval(study);
  if (all.empty()) return out + "No parameter vectors.\n\n";
  MarkdownTable table({"T_s [ms]", "OLS tr Σ_z (n)", "SDP tr Σ_z (n)", "CLIE tr Σ_z (n)", "CLIE / OLS"});
  for (const auto& d : all) {
    std::vector<std::string> row{std::isnan(d.interval) ? "All" : std::to_string(interval_ms(d.interval))};
    for (int s = 0; s < 3; ++s) row.push_back(fmt::format("{} ({})", sig(d.trace[s], 4), d.count[s]));
    row.push_back(sig(d.trace[2] / d.trace[0], 3));
    table.row(row);
  }
  return out + table.str() +
         "\ntr Σ_z: trace of the sample covariance of the standardized parameters "
         "z = (φ − mean) / scale over the runs at that interval; smaller is a tighter cloud.\n\n";
}

std::string central_runs_table(const StudyResult& study, int count) {
  const auto& c = study.selection.centrality;
  if (c.size() != study.runs.size() || c.empty()) return {};
  std::vector<int> order(c.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    if (std::isnan(c[a]) != std::isnan(c[b])) return std::isnan(c[b]);
    return c[a] < c[b];
  });
  MarkdownTable table({"Rank", "Run", "Centrality", "CLIE PD", "Selected"});
  for (int k = 0; k < std::min<int>(count, static_cast<int>(order.size())); ++k) {
    const int i = order[k];
    table.row({std::to_string(k + 1), study.runs[i].id(), sig(c[i], 4), yes_no(study.runs[i].clie_pd),
               i == study.selection.run ? "yes" : ""});
  }
  return "### Most central CLIE candidates\n\n" + table.str() + "\n";
}

std::string appendix_record(const StudyResult& study) {
  std::string out = "## Appendix A: run record\n\n";
  if (study.runs.empty()) return out + "No runs.\n\n";
  out +=
      "κ: σ_max/σ_min of the stacked regressor W; κ scaled: the same with unit-norm columns. "
      "OLS PD and λ_min: the all-pose audit of the OLS estimate. Cost reduction: 1 − final/initial "
      "CLIE cost. Times in s.\n\n";
  std::vector<int> order(study.runs.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const auto &ra = study.runs[a], &rb = study.runs[b];
    const auto ka = std::make_tuple(family(ra.trajectory), ra.trajectory, ra.interval);
    const auto kb = std::make_tuple(family(rb.trajectory), rb.trajectory, rb.interval);
    return ka < kb;
  });
  const std::vector<std::string> header{"Trajectory", "T_s [ms]", "κ",     "κ scaled",       "OLS PD",  "OLS λ_min",
                                        "Route",      "ε_PD",     "CLIE",  "Cost reduction", "CLIE PD", "CLIE λ_min",
                                        "t_OLS",      "t_audit",  "t_SDP", "t_CLIE"};
  std::size_t k = 0;
  while (k < order.size()) {
    const std::string fam = family(study.runs[order[k]].trajectory);
    MarkdownTable table(header);
    for (; k < order.size() && family(study.runs[order[k]].trajectory) == fam; ++k) {
      const RunRecord& r = study.runs[order[k]];
      table.row({r.trajectory, std::to_string(interval_ms(r.interval)), fixed(r.kappa, 1), fixed(r.kappa_scaled, 1),
                 r.ols_pd ? "Y" : "N", sig(r.ols_lambda_min, 3), r.route.empty() ? "n/a" : r.route, eps_text(r),
                 clie_status(r), cost_reduction(r), r.clie_pd ? "Y" : "N", sig(r.clie_lambda_min, 3), fixed(r.t_ols, 2),
                 fixed(r.t_audit, 2), fixed(r.t_sdp, 2), fixed(r.t_clie, 1)});
    }
    out += "### " + fam + "\n\n" + table.str() + "\n";
  }
  return out;
}

std::string parameter_table(const StudyResult& study) {
  std::string out = "## Final parameters\n\n";
  const int np = parameter_count(study);
  if (np == 0) return out + "No parameters.\n\n";
  const RunRecord* r = selected_run(study);
  const bool truth = study.truth.size() == np;
  const Eigen::VectorXd none;
  const Eigen::VectorXd& ols = r ? r->phi_ols : none;
  const Eigen::VectorXd& std_ols = r ? r->std_ols : none;
  const Eigen::VectorXd& sdp = r ? r->phi_sdp : none;
  const Eigen::VectorXd& clie = r ? r->phi_clie : none;
  std::vector<std::string> header{"Parameter", "Unit", "OLS", "OLS std", "SDP", "CLIE", "Accepted"};
  if (truth) header.insert(header.end(), {"Truth", "Error", "Rel. error"});
  MarkdownTable table(header);
  for (int i = 0; i < np; ++i) {
    std::vector<std::string> row{name_of(study, i),
                                 unit_of(study, i),
                                 value_or_dash(ols, i, np),
                                 value_or_dash(std_ols, i, np),
                                 value_or_dash(sdp, i, np),
                                 value_or_dash(clie, i, np),
                                 value_or_dash(study.phi_rescue, i, np)};
    if (truth) {
      row.push_back(sig(study.truth(i), 6));
      if (study.phi_rescue.size() == np) {
        const double error = study.phi_rescue(i) - study.truth(i);
        row.push_back(sig(error, 3));
        row.push_back(study.truth(i) != 0 ? fixed(100 * std::abs(error / study.truth(i)), 2) + " %" : "n/a");
      }
    }
    table.row(row);
  }
  out += r ? fmt::format("OLS, SDP and CLIE of the representative {}; Accepted: ", r->id()) : "Accepted: ";
  out += study.rescued ? (study.consistency == "physical" ? "the vector rescued onto the physically consistent set"
                                                          : "the PD-rescued vector")
                       : "the CLIE vector as accepted";
  out += " (full precision in parameters.yaml / parameters.csv).\n\n" + table.str() + "\n";
  if (truth && study.phi_rescue.size() == np)
    out += fmt::format("‖φ − φ_true‖₂ / ‖φ_true‖₂ = {}.\n\n",
                       sig((study.phi_rescue - study.truth).norm() / study.truth.norm(), 4));
  return out;
}

}  // namespace symoro::study::report_detail
