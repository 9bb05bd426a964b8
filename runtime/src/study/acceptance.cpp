// The acceptance rule's steps (acceptance.hpp).
#include "symoro/study/acceptance.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "pca.hpp"

namespace symoro::study {

std::optional<Representative> select_representative(const std::vector<RunRecord>& runs, int pca_components,
                                                    double variance_fraction) {
  Representative out;
  int usable = 0;
  for (const RunRecord& r : runs) usable += !r.failed && r.phi_clie.size() > 0;
  if (usable == 0) return std::nullopt;
  if (runs.size() == 1) {  // one run (--only X --interval h): it is the candidate, no cloud
    out.selection.run = 0;
    out.selection.centrality = {0.0};
    out.selection.rule = "the only run (no PCA cloud)";
    return out;
  }
  out.pca = pca_clouds(runs, pca_components);
  out.selection = select_central(runs, out.pca, variance_fraction);
  return out;
}

PriorWeightChoice choose_prior_weight(const std::vector<double>& weights, double default_weight,
                                      const std::function<identify::PhysicalProjection(double)>& rescue,
                                      const std::function<double(const Eigen::VectorXd&)>& heldout_rmse) {
  PriorWeightChoice out;
  out.weight = default_weight;
  double best = std::numeric_limits<double>::infinity();
  for (const double w : weights) {
    identify::PhysicalProjection p = rescue(w);
    const double rmse = heldout_rmse(p.phi);
    out.scores.emplace_back(w, rmse);
    if (p.feasible && (out.projection.phi.size() == 0 || rmse < best * (1 - 1e-3))) {
      best = rmse;
      out.projection = std::move(p);
      out.weight = w;
    }
  }
  if (out.projection.phi.size() == 0) out.projection = rescue(default_weight);
  return out;
}

identify::AuditOptions final_audit_options(const identify::AuditOptions& pipeline,
                                           const FinalAuditOptions& final_audit) {
  identify::AuditOptions a = pipeline;
  a.samples *= final_audit.sample_factor;
  a.starts *= final_audit.start_factor;
  a.seed += final_audit.seed_offset;
  return a;
}

std::string describe(const identify::AuditOptions& a) {
  return fmt::format("{} quasi-random poses, {} local minimizations, seed {}", a.samples, a.starts, a.seed);
}

Verdict acceptance_verdict(const StudyResult& r) {
  Verdict v;
  if (r.selection.run < 0) {
    v.reasons.push_back("no representative run: " +
                        (r.selection.rule.empty() ? "no run produced a final vector" : r.selection.rule));
    return v;
  }
  const bool positive_definite = r.final_lambda_min > 0;  // AuditResult::positive_definite()
  const bool consistent = r.consistency != "physical" || r.final_consistent;
  v.accepted = positive_definite && consistent;
  if (v.accepted) return v;
  if (!positive_definite)
    v.reasons.push_back(
        fmt::format("the final audit found M(q) not positive definite (lambda_min {:.4g})", r.final_lambda_min));
  if (!consistent)
    v.reasons.push_back("no physically consistent set maps onto it" +
                        (r.final_consistency_note.empty() ? std::string() : " (" + r.final_consistency_note + ")"));
  // What the vector came from, when its rescue did not finish.
  if (r.rescued && !r.rescue_feasible) v.reasons.push_back("the rescue's projection failed (" + r.rescue_status + ")");
  return v;
}

}  // namespace symoro::study
