// The study's physical path (dynid identify --consistency physical): instead of the all-pose PD
// constraint on M(q) (sdp_projection.hpp, sampled poses), a base vector is admissible when a
// physically consistent standard set maps onto it (physical_consistency.hpp: per-link
// pseudo-inertia LMIs, IA, FV, FS >= 0). That is sufficient for M(q) > 0 at every pose, where the
// sampled audit is only necessary, and the exported URDF then reproduces the accepted vector.
//   check:    does phi0 have a consistent standard set? (phase 1 of the solve)
//   project:  if not, the nearest base vector that has one, in a metric of the caller's (the
//             run's predicted torque), each link's pseudo-inertia clearing `clearance` times its
//             size; a variant's fixed parameters stay exactly where they are.
// A variant's effect parameters (offsets, friction laws, harmonics: dynid diagnose --apply) take
// part in the same solve: they follow the parent's base vector in the target and are free, or
// >= 0 where the effect is physical only with a positive level (Coulomb, Stribeck), so a
// projection moves them with the rigid body's parameters to the nearest point in the metric.
// The projection is then checked again as the accepted vector will be: one solve from scratch.
#pragma once

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <fmt/format.h>

#include "symoro/identify/detail/physical_consistency_model.hpp"

namespace symoro::identify {

struct PhysicalProjection {
  ConsistencyResult check;  // of phi0 (with the projection's search when it has no consistent set)
  bool consistent = false;  // phi0 has a consistent standard set: phi = phi0
  bool projected = false;   // it had none: phi is the nearest base vector that has one
  bool feasible = false;    // phi has a consistent standard set (verified by its own solve)
  Eigen::VectorXd phi;      // the model's base vector (phi0 when not projected or when it failed)
  // The smallest pseudo-inertia eigenvalue margin of phi relative to the links' size (phase 1's
  // t of physical_consistency.hpp; < 0: no consistent set). NaN when the prior's own projection
  // onto phi was consistent (phase 1 not needed).
  double margin = std::numeric_limits<double>::quiet_NaN();
  double distance = 0;  // |R (phi - phi0)| in the caller's metric (0 when not projected)
  std::string status;   // one sentence
  double wall = 0;      // s
};

// Where entry i of a Model's phi sits in its consistency target (consistency_target): the
// parent's base row, or after the parent's rows for an effect parameter.
template <class Model>
int target_row(int i) {
  const int parent = Model::parent_index[static_cast<std::size_t>(i)];
  return parent >= 0 ? parent : Model::Parent::np + i - (Model::np - detail::effect_count<Model>());
}

// The target's rows a variant fixes (empty for a full model), 0-based.
template <class Model>
std::vector<int> fixed_parent_rows() {
  constexpr int rows = Model::Parent::np + detail::effect_count<Model>();
  std::vector<int> free(rows, 0), held;
  for (int i = 0; i < Model::np; ++i) free[static_cast<std::size_t>(target_row<Model>(i))] = 1;
  for (int i = 0; i < rows; ++i)
    if (!free[static_cast<std::size_t>(i)]) held.push_back(i);
  return held;
}

// The root R (R'R = metric) of a metric on the model's phi, as a metric root on its consistency
// target: the variant's columns where they sit in the target, zero on the fixed rows.
template <class Model>
Eigen::MatrixXd parent_metric_root(const Eigen::MatrixXd& metric) {
  const Eigen::MatrixXd R = metric.llt().matrixU();
  Eigen::MatrixXd Rp = Eigen::MatrixXd::Zero(Model::np, Model::Parent::np + detail::effect_count<Model>());
  for (int i = 0; i < Model::np; ++i) Rp.col(target_row<Model>(i)) = R.col(i);
  return Rp;
}

// A model's phi from its consistency target (the inverse of consistency_target on the variant's
// rows; the fixed rows are dropped).
template <class Model>
Eigen::VectorXd from_target(const Eigen::VectorXd& target) {
  constexpr int ne = detail::effect_count<Model>();
  const Eigen::Matrix<double, Model::Parent::np, 1> full = target.head(Model::Parent::np);
  Eigen::VectorXd phi = Model::from_parent(full).template cast<double>();
  phi.tail(ne) = target.tail(ne);
  return phi;
}

template <class Model>
constexpr bool supports_physical_consistency() {
  return Model::Parent::ns == Model::ns - detail::effect_count<Model>();
}

// Whether phi has a physically consistent standard set (phase 1 only: ok(), feasibility). A
// zero prior (empty) scales the solve by the smallest standard vector mapping onto phi. A prior
// of the parent's size gets 0 for the effect parameters.
template <class Model>
ConsistencyResult physical_check(const Eigen::VectorXd& phi, Eigen::VectorXd prior = {}) {
  static_assert(supports_physical_consistency<Model>());
  prior = detail::standard_prior(prior, Model::ns, detail::effect_count<Model>());
  ConsistencyOptions o;
  o.feasibility_only = true;
  return consistent_standard_parameters<Model>(phi, prior, o);
}

// metric: symmetric positive definite np x np (e.g. the run's W'W / rows); prior: standard
// parameters (empty: zero, see physical_check); options: the solve's
// (prior regularization, tolerances); its held rows, metric and clearance are set here.
template <class Model>
PhysicalProjection physical_projection(const Eigen::VectorXd& phi0, Eigen::VectorXd prior,
                                       const Eigen::MatrixXd& metric, double clearance,
                                       ConsistencyOptions options = {}) {
  static_assert(supports_physical_consistency<Model>());
  const auto t0 = std::chrono::steady_clock::now();
  PhysicalProjection p;
  p.phi = phi0;
  if (metric.rows() != Model::np || metric.cols() != Model::np)
    throw std::invalid_argument("physical_projection: the metric must be np x np");
  prior = detail::standard_prior(prior, Model::ns, detail::effect_count<Model>());
  options.held_rows = fixed_parent_rows<Model>();
  options.base_metric_root = parent_metric_root<Model>(metric);
  options.infeasible_clearance = clearance;
  p.check = consistent_standard_parameters<Model>(phi0, prior, options);
  p.margin = p.check.feasibility;
  if (p.check.ok()) {
    p.consistent = p.feasible = true;
    p.status = "consistent: " + p.check.message;
  } else if (p.check.status == ConsistencyStatus::NoConsistentSet &&
             p.check.phi_consistent.size() == options.base_metric_root.cols()) {
    p.projected = true;
    p.phi = from_target<Model>(p.check.phi_consistent);
    p.distance =
        (options.base_metric_root * (consistency_target<Model>(p.phi) - consistency_target<Model>(phi0))).norm();
    const ConsistencyResult v = physical_check<Model>(p.phi, prior);
    p.feasible = v.ok();
    p.margin = v.feasibility;
    p.status = p.feasible
                   ? fmt::format("projected onto the consistent set (distance {:.4g}); {}", p.distance, v.message)
                   : fmt::format("the projection has no consistent set after all: {}", v.message);
    if (!p.feasible) p.phi = phi0;
  } else {
    p.status = p.check.message;
  }
  p.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return p;
}

}  // namespace symoro::identify
