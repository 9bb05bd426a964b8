// All-pose positive-definiteness audit of M(q; phi) over a box of joint angles (paper eq.
// pd_check_lambda), built not to trust a grid: dense quasi-random sampling finds the basins,
// then local minimizations of the Rayleigh quotient v'M(q)v subject to |v| = 1 (Ipopt, exact
// derivatives from Jets, q inside the box) descend to the worst poses between the samples.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/inertia_function.hpp"

namespace symoro::identify {

struct AuditOptions {
  int samples = 4096;        // dense quasi-random poses over the box (plus its centre)
  int starts = 12;           // local minimizations, from the best distinct samples
  std::uint64_t seed = 1;    // scrambles the quasi-random sequence
  int max_iterations = 200;  // per local minimization
  double tolerance = 1e-12;  // Ipopt's convergence tolerance
  // More starting poses (e.g. the worst poses of a previous audit), minimized too.
  std::vector<Eigen::VectorXd> extra_starts;
};

struct AuditPose {
  Eigen::VectorXd q;
  double lambda_min = 0;  // smallest eigenvalue of M at q
};

struct AuditResult {
  double lambda_min = 0;          // the smallest eigenvalue found over the box
  Eigen::VectorXd worst_pose;     // where
  std::vector<AuditPose> minima;  // distinct local minima (and best samples), worst first
  int sampled = 0;                // poses evaluated by sampling
  int local_searches = 0;         // Ipopt runs
  double wall = 0;                // s
  bool positive_definite(double margin = 0) const { return lambda_min > margin; }
};

// Throws std::invalid_argument on a domain or phi of the wrong size or lower > upper.
AuditResult audit_pd(const InertiaFunction& m, const Eigen::VectorXd& phi, const AuditDomain& domain,
                     const AuditOptions& options = {});

// The grid audit a paper-style check would do: points_per_joint equally spaced values per joint
// (2: the bounds; 3: bounds and middle), every combination. For comparison and tests.
AuditResult grid_audit(const InertiaFunction& m, const Eigen::VectorXd& phi, const AuditDomain& domain,
                       int points_per_joint);

}  // namespace symoro::identify
