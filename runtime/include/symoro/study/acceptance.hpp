// How a study accepts the model it identified: the rule, step by step in the order Study::run
// applies it after the runs (docs/identification.md, "Acceptance").
//   1. The representative (select_representative): the run whose CLIE vector is nearest the
//      centre of the runs' PCA cloud, the paper's selection.
//   2. The rescue, when that vector is not admissible on the study's path (StudyOptions::
//      consistency): the physical path projects it onto the physically consistent set
//      (IdentificationModel::physical_projection, in a predicted-torque metric, towards the
//      prior), the PD path onto the all-pose PD set with eps 0 (project_pd: the paper's minimal
//      correction). Both need the study's data, so Study forms them; this header holds the rest.
//   3. The prior's weight (choose_prior_weight), when StudyOptions::rescue_prior_weights gives
//      several: the rescue under each, scored on held-out runs.
//   4. The final audit (final_audit_options): the all-pose audit again, denser than the
//      pipeline's and on poses it never saw.
//   5. The verdict (acceptance_verdict): accepted, or the reasons it is not.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/pd_audit.hpp"
#include "symoro/identify/physical_projection.hpp"
#include "symoro/study/result.hpp"

namespace symoro::study {

// 1. The representative and the clouds it was chosen in (empty clouds for a study of one run,
//    which is its own representative); nullopt when no run produced a final vector.
struct Representative {
  Selection selection;  // selection.run < 0: the clouds chose none (selection.rule says why)
  PcaClouds pca;
};
std::optional<Representative> select_representative(const std::vector<RunRecord>& runs, int pca_components,
                                                    double variance_fraction);

// 3. The rescue under each of `weights`, scored by `heldout_rmse` of its vector (N m, the open-loop
//    RMSE on the identification runs other than the representative's): the smallest error among
//    the feasible rescues wins, the smaller weight on a tie within 0.1 %. None feasible: the rescue
//    under `default_weight`.
struct PriorWeightChoice {
  identify::PhysicalProjection projection;
  double weight = 0;
  std::vector<std::pair<double, double>> scores;  // weight, held-out RMSE (N m), in the order tried
};
PriorWeightChoice choose_prior_weight(const std::vector<double>& weights, double default_weight,
                                      const std::function<identify::PhysicalProjection(double)>& rescue,
                                      const std::function<double(const Eigen::VectorXd&)>& heldout_rmse);

// 4. The final audit's settings, relative to the pipeline's audit (StudyOptions::audit).
struct FinalAuditOptions {
  int sample_factor = 4;             // times the pipeline audit's quasi-random poses
  int start_factor = 2;              // times its local minimizations
  std::uint64_t seed_offset = 7919;  // added to its seed: another scrambling, poses it never saw
};
identify::AuditOptions final_audit_options(const identify::AuditOptions& pipeline,
                                           const FinalAuditOptions& final_audit);
// One line for the report: the settings as numbers.
std::string describe(const identify::AuditOptions& final_audit);

// 5. The verdict on the study's accepted vector (StudyResult's rescue and final fields): M(q) > 0
//    at every pose the final audit tried, and on the physical path a consistent standard set that
//    maps onto it. `reasons`: why it is not accepted, one line each (empty when accepted).
struct Verdict {
  bool accepted = false;
  std::vector<std::string> reasons;
};
Verdict acceptance_verdict(const StudyResult& r);

}  // namespace symoro::study
