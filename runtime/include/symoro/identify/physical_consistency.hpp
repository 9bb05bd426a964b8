// Physically consistent standard parameters from an accepted base-parameter vector:
//   min |W (s - s0)|^2  s.t.  B s = phi,  J_k(s) >= margin I (every link k),  lower <= s <= upper,
// s the standard parameters (per link: XX..ZZ about the frame origin, MX MY MZ, M, IA, FV, FS),
// B the generated base_from_standard as a matrix, s0 a prior (CAD or nominal values) and J_k the
// link's pseudo-inertia (Wensing, Kim, Slotine 2017):
//   J = [[0.5 tr(I) 1 - I, h], [h', m]],  I the inertia about the frame origin, h = (MX, MY, MZ);
// J >= 0 is exactly physical consistency (m >= 0, the CoM's second moment PSD, the triangle
// inequalities about the CoM). Solved with CSDP, the equality eliminated (s on B's affine
// solution set) so that B s = phi holds to rounding whatever CSDP's tolerance.
// When no consistent s maps onto phi the answer says so: status NoConsistentSet, with the
// nearest base vector that has one (phi_consistent) and its distance. Nothing is forced.
// For a generated Model, physical_consistency_model.hpp builds the structure.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::identify {

// The indices into s of one link's inertial parameters, in the order
// XX XY XZ YY YZ ZZ MX MY MZ M; -1 where the model has no such parameter (taken as 0).
struct LinkInertialIndices {
  int link = 0;  // 1-based link (frame) number
  std::array<int, 10> index{{-1, -1, -1, -1, -1, -1, -1, -1, -1, -1}};
};

// Weight groups of the default metric (see default_consistency_weights).
enum class StandardGroup { Mass, FirstMoment, Inertia, RotorInertia, Viscous, Coulomb, Other };

struct ConsistencyStructure {
  Eigen::MatrixXd B;                       // np x ns: phi = B s
  std::vector<std::string> names;          // ns standard parameter names (messages)
  std::vector<StandardGroup> group;        // ns
  std::vector<LinkInertialIndices> links;  // links with at least one inertial parameter
  std::vector<int> nonnegative;            // IA, FV, FS: lower bound 0 unless options say otherwise
};

struct ConsistencyOptions {
  // J_k - margin I >= 0. One number for the whole 4 x 4 matrix, so in kg m^2 on the second-moment
  // block and kg on the mass: meant as a small strictness guard (e.g. 1e-6), not as a physical
  // bound; use lower/upper for those.
  double margin = 0;
  // Diagonal metric of |W (s - s0)| (size ns); empty: default_consistency_weights(prior, phi).
  Eigen::VectorXd weights;
  // Bounds on s (size ns each, +-inf for none); empty: 0 below for `nonnegative`, nothing else.
  Eigen::VectorXd lower, upper;
  // Diagonal metric of the base-space distance |W_b (phi_c - phi)| reported when phi has no
  // consistent set (size np); empty: 1 / |row i of B diag(1 / weights)|, i.e. each base
  // parameter in the scale of the standard parameters it combines.
  Eigen::VectorXd base_weights;
  // A full metric instead (it wins over base_weights): distance |R (phi_c - phi)|, R with one
  // column per base parameter. With R = the R factor of a run's regression W / sqrt(rows), the
  // distance is the RMS change of the predicted torque on that run, and phi_c the consistent
  // base vector that changes it least (dynid export --data).
  Eigen::MatrixXd base_metric_root;
  // No consistent set: entries of phi that phi_consistent keeps exactly (0-based rows of B), e.g.
  // the parameters a variant fixes (the study's physical projection of crane_x7::reduced keeps
  // its products of inertia at 0); the base metric then weighs the other rows only.
  std::vector<int> held_rows;
  // A phase-1 verdict t >= -feasibility_tolerance (t: the smallest eigenvalue margin relative to
  // each link's size) counts as feasible; the solve then asks for margin + t (a touch below).
  double feasibility_tolerance = 1e-10;
  // Phase 1 searches |W (s - s0)| <= trust_radius * (1 + |W (s_p - s0)|), s_p the
  // prior's projection onto B s = phi: consistent sets farther than that are not looked for.
  double trust_radius = 1e3;
  // No consistent set: phi_c is the nearest base vector whose standard set clears the margin by
  // this fraction of each link's size (so that phi_c is itself strictly feasible), the standard set
  // regularized towards the prior with this relative weight.
  double infeasible_clearance = 1e-7;
  double prior_regularization = 1e-6;
  // Only ask whether phi has a consistent set (phase 1): s is then phase 1's set (consistent, but
  // not the one nearest the prior) and, when there is none, the nearest base vector is not sought.
  bool feasibility_only = false;
};

enum class ConsistencyStatus {
  Consistent,       // s is consistent and B s = phi
  NoConsistentSet,  // no consistent s maps onto phi: see phi_consistent, base_distance
  SolverFailure,    // CSDP failed (message says how); s is the best it returned, unchecked
};

struct ConsistencyResult {
  ConsistencyStatus status = ConsistencyStatus::SolverFailure;
  std::string message;  // one sentence: why this status
  bool ok() const { return status == ConsistencyStatus::Consistent; }

  Eigen::VectorXd s;                // Consistent: the answer; NoConsistentSet: a consistent set for phi_consistent
  Eigen::VectorXd link_lambda_min;  // lambda_min(J_k(s)) per structure.links entry
  double lambda_min = 0;            // the smallest of them (+inf without links)
  double residual = 0;              // max |B s - phi|
  double prior_distance = 0;        // |W (s - s0)|
  // Phase 1: max t with J_k(s) >= (margin + t c_k) I, B s = phi (c_k the link's size); < 0: no
  // consistent set at this margin. NaN when phase 1 was not needed (the prior's projection was
  // already consistent).
  double feasibility = 0;

  // NoConsistentSet only: phi_consistent = B s, and |W_b (phi_consistent - phi)| (|R (...)| with
  // base_metric_root).
  Eigen::VectorXd phi_consistent;
  double base_distance = 0;

  int solves = 0;   // CSDP solves
  double wall = 0;  // s
};

const char* to_string(ConsistencyStatus s);

// The default metric: one scale per group (mass; first moments; XX..ZZ; rotor inertia; FV; FS;
// other), the root mean square of the prior's entries of that group; where they are all 0 (a
// zero prior), of that group's entries in the smallest standard vector mapping onto phi
// (B^+ phi; without phi, or when those are 0 too: 1); weight = 1 / scale. Masses, first moments
// and inertias then weigh alike: a 10 % change of a typical value costs the same in each.
Eigen::VectorXd default_consistency_weights(const ConsistencyStructure& structure, const Eigen::VectorXd& prior,
                                            const Eigen::VectorXd& phi = {});

// J_k of one link for a standard vector s.
Eigen::Matrix4d pseudo_inertia(const Eigen::VectorXd& s, const LinkInertialIndices& link);

// Throws std::invalid_argument on inconsistent sizes or non-finite input.
ConsistencyResult consistent_standard_parameters(const ConsistencyStructure& structure, const Eigen::VectorXd& phi,
                                                 const Eigen::VectorXd& prior, const ConsistencyOptions& options = {});

}  // namespace symoro::identify
