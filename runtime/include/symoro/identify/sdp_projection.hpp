// The PD-feasible projection (paper eqs. sdp_projection and sdp_rescue):
//   min |phi - phi0|^2  s.t.  M(q_k; phi) >= eps I  for the poses q_k of a working set,
// in the Euclidean norm (the paper's; optionally diagonally weighted) or in a metric
// (phi - phi0)' A (phi - phi0), e.g. the run's information matrix, so that the projection
// changes the predicted torque as little as possible (information_metric below),
// solved as a semidefinite program with CSDP (the distance through a Schur-complement block),
// inside an exchange loop: the all-pose audit looks for poses where the solution still has
// lambda_min below the margin, the worst of them join the working set, and the SDP is solved
// again until the audit passes over the whole box.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/inertia_function.hpp"
#include "symoro/identify/pd_audit.hpp"

namespace symoro::identify {

struct ProjectionOptions {
  double eps = 0.001;  // margin, in M's units (kg m^2)
  // The audit's verdict accepts lambda_min >= eps - accept_slack; for eps = 0 (the post-CLIE
  // rescue) the SDP itself uses rescue_floor so that the strict test lambda_min > 0 holds.
  double accept_slack = 1e-9;
  double rescue_floor = 1e-7;
  int max_rounds = 30;      // exchange rounds
  int poses_per_round = 4;  // worst distinct audit minima added per round
  // The exchange ends slowly: each new pose's basin minimum drifts a little as phi moves, so the
  // audit's shortfall shrinks by a small factor per round. When > 0, each round also raises the
  // SDP's margin by this fraction of the audit's shortfall (accumulated): fewer rounds for a
  // slightly larger distance (CRANE-X7, eps = 0.001: 0.5 ends in 2 rounds instead of about 6,
  // the distance about 1e-4 larger in relative terms). The raise stays below max(eps, 1 % of
  // phi0's violation): a large shortfall is a new basin, not drift. 0: the plain exchange.
  double shortfall_raise = 0;
  AuditOptions audit;  // the audit run after each solve
  // Diagonal weights of the distance (empty: the paper's plain Euclidean norm).
  Eigen::VectorXd weights;
  // A symmetric positive definite np x np metric A: the distance is sqrt(d' A d), d = phi - phi0
  // (empty: weights). With a full A every parameter may move, friction included: the ones M does
  // not contain then absorb what the projection does to the torque.
  Eigen::MatrixXd metric;
};

// The information metric of a regression: W'W / sigma^2 (W the stacked, weighted rows), with a
// ridge of `ridge` times its mean diagonal so that it is positive definite even where W barely
// excites a direction. The distance in it is the change of the predicted torque in noise units.
Eigen::MatrixXd information_metric(const Eigen::MatrixXd& information, double ridge = 1e-9);

struct ProjectionResult {
  Eigen::VectorXd phi;
  bool feasible = false;  // the final all-pose audit passed at the margin
  double eps = 0;         // the margin asked for
  double lambda_min = 0;  // from the final audit
  Eigen::VectorXd worst_pose;
  double distance = 0;  // |phi - phi0| (weighted when weights are given)
  int rounds = 0;       // exchange rounds, one SDP each (project_on_poses: CSDP solves)
  int poses = 0;        // working-set size at the end
  std::string status;   // "ok", or CSDP's failure / why the loop stopped
  double wall = 0;      // s
};

// The working set starts with the domain's centre and the worst minima of phi0's audit; round r
// audits with seed options.audit.seed + r, descending also from every working-set pose. Not PD
// after max_rounds or an SDP failure: feasible = false, phi the last SDP solution. Safe to call
// from several threads (CSDP's solves are serialized: it keeps static state).
ProjectionResult project_pd(const InertiaFunction& m, const Eigen::VectorXd& phi0, const AuditDomain& domain,
                            const ProjectionOptions& options = {});
// The same when the caller has already audited phi0 (its minima seed the working set).
ProjectionResult project_pd(const InertiaFunction& m, const Eigen::VectorXd& phi0, const AuditDomain& domain,
                            const ProjectionOptions& options, const AuditResult& phi0_audit);

// The SDP on a fixed set of poses: min |W(phi - phi0)|^2 s.t. M(q_k; phi) >= eps I for every
// pose q_k (W = diag(weights); empty: identity; or W'W = metric when a metric is given).
// feasible: CSDP solved it and every pose reaches
// eps within 1e-10; lambda_min and worst_pose are over these poses only; rounds counts the CSDP
// solves (the scaling and accuracy refinements); rounds = 0 when phi0 already satisfies them.
// Without a metric, parameters that enter M at none of the poses keep their phi0 values exactly.
ProjectionResult project_on_poses(const InertiaFunction& m, const Eigen::VectorXd& phi0,
                                  const std::vector<Eigen::VectorXd>& poses, double eps,
                                  const Eigen::VectorXd& weights = {}, const Eigen::MatrixXd& metric = {});

// The paper's conditional step (Algorithm 1, lines 4-15): audit phi0; when it is not PD,
// project with the margins in ascending order and adopt the first one whose projection passes
// the all-pose audit. When none does: feasible = false, phi = phi0 and eps = 0 (a failed
// projection is never handed on); the attempts keep what each margin reached.
struct ConditionalProjection {
  AuditResult audit;                       // of phi0
  bool projected = false;                  // false: phi0 was PD and is returned unchanged
  bool feasible = false;                   // phi is PD over the box
  double eps = 0;                          // the adopted margin (0 when not projected)
  Eigen::VectorXd phi;                     // the CLIE starting point (phi0 when not feasible)
  std::vector<ProjectionResult> attempts;  // one per margin tried
};

inline const std::vector<double>& paper_margins() {
  static const std::vector<double> v{0.001, 0.002, 0.005, 0.01};
  return v;
}

ConditionalProjection conditional_projection(const InertiaFunction& m, const Eigen::VectorXd& phi0,
                                             const AuditDomain& domain,
                                             const std::vector<double>& margins = paper_margins(),
                                             const ProjectionOptions& options = {});

}  // namespace symoro::identify
