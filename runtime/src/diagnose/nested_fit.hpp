// The selection's least squares (selection.hpp), apart from its decisions: the stacked design
// of a model with effects, its weighted solve, and a design solved once against which
// candidate columns are added one set at a time (Frisch-Waugh: only the candidate's part
// orthogonal to the design is solved for), on the training and the held-out stacks.
#pragma once

#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "symoro/diagnose/effects.hpp"
#include "symoro/diagnose/selection.hpp"

namespace symoro::diagnose::detail {

// Per-row weights (row s * n + j gets w_j).
Eigen::VectorXd row_weights(const DesignStack& d, const Eigen::VectorXd& w);
// A stacked (samples * joints) vector as samples x joints.
Eigen::MatrixXd per_sample(const DesignStack& d, const Eigen::VectorXd& stacked);
Eigen::VectorXd joint_rms(const DesignStack& d, const Eigen::VectorXd& r);
// The identified parameters the fit estimates: all of them, or none when they are held.
Eigen::Index free_parameters(const DesignStack& d);
// The current model's design on a stack: W (unless its parameters are held), then each
// effect's columns (evaluated at `state`).
Eigen::MatrixXd design(const DesignStack& d, const std::vector<Candidate>& effects, const FitState& state);

// Weighted LS with unit-norm columns: beta and, optionally, its covariance factor.
struct Solve {
  Eigen::VectorXd beta;
  Eigen::VectorXd sd;   // sqrt(diag(sigma^2 (A'WA)^-1)), times sqrt(autocorrelation time)
  Eigen::MatrixXd cov;  // sigma^2 tau_int (A'WA)^-1, in beta's units
};
// Scales the columns of As to unit norm (zero columns stay) and returns the scales: the
// candidates' units differ by orders of magnitude.
Eigen::VectorXd unit_columns(Eigen::MatrixXd& As);
Solve weighted_ls(const Eigen::MatrixXd& A, const Eigen::VectorXd& y, const Eigen::VectorXd& rw, double tau_int);

FitState state_of(const DesignStack& d, const Eigen::MatrixXd& A, const Eigen::VectorXd& beta, Eigen::Index np);
FitState base_state(const DesignStack& d, const Eigen::VectorXd& phi);
// Whether some effect's columns depend on the fit (evaluated about its torques).
bool linearized(const std::vector<Candidate>& effects);
double pooled_time(const Eigen::VectorXd& tau);
// Held-out weighted SSE of a fit on the joints in `on` (all when empty).
double heldout_sse(const Fit& f, const Eigen::VectorXd& weights, const std::vector<int>& on, int samples);

// A model's design on both stacks, weighted and solved once: its residuals, and what adding
// columns to it needs.
struct NestedDesign {
  const DesignStack* train = nullptr;
  const DesignStack* heldout = nullptr;
  Eigen::MatrixXd A, Ah;                // unweighted designs
  Eigen::MatrixXd As;                   // weighted, unit-norm columns
  Eigen::VectorXd scale;                // As's column scales
  Eigen::VectorXd rw, rwh;              // row weights
  Eigen::VectorXd beta;                 // in A's units
  Eigen::VectorXd r, rh;                // weighted residuals, train and held out
  Eigen::LDLT<Eigen::MatrixXd> Gf;      // of As'As
  bool empty = false;                   // no column (held parameters, no effect): the residual is y
  FitState train_state, heldout_state;  // its torques, for linearized candidates
};
// `effects` evaluated about `current`'s torques (a fit of those same effects).
NestedDesign nested_design(const DesignStack& train, const DesignStack& heldout, const std::vector<Candidate>& effects,
                           const Fit& current, const Eigen::VectorXd& weights);

// Columns added to a nested design (weighted by its rows, unit norm), solved for together
// with it.
struct AddedColumns {
  bool absorbed = false;           // a zero column, or in the design's span: nothing to solve
  Eigen::MatrixXd C;               // weighted, unit-norm columns
  Eigen::VectorXd cs;              // their scales
  Eigen::MatrixXd K;               // (As'As)^-1 As'C
  Eigen::MatrixXd ZZ;              // C'C - C'As K: the information of C's part orthogonal to As
  Eigen::VectorXd Cr;              // C'r
  Eigen::VectorXd theta_s, theta;  // unit-norm and in the columns' units
  double reduction = 0;            // of the training residual's weighted sum of squares
  Eigen::VectorXd rh1;             // the held-out weighted residual of the refit with them
};
// Ctr, Ch: the columns on the training and the held-out stacks.
AddedColumns add_columns(const NestedDesign& d, const Eigen::MatrixXd& Ctr, const Eigen::MatrixXd& Ch);

// Weighted held-out SSE of a residual on one 1-based joint (0: all).
double joint_sse(const DesignStack& heldout, const Eigen::VectorXd& r, int joint);

}  // namespace symoro::diagnose::detail
