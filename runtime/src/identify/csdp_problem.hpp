// A linear matrix inequality program solved with CSDP (private to the SDP projection):
//   minimize b'y  subject to  F_k(y) = F_k0 + sum_i y_i F_ki  psd,  k = 0..blocks-1.
// This is CSDP's dual problem (A'(y) - C = Z psd) with A_i's block k = F_ki, C's block k = -F_k0
// and a = b; the class hides CSDP's 1-based, linked-list data structures and its allocations.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::identify::detail {

struct LmiSettings {
  // CSDP's relative primal and dual infeasibility and gap (axtol, atytol, objtol). CSDP's own
  // default 1e-8 bounds the objective; a squared-distance objective is flat at the optimum, so
  // the solution itself is only accurate to about the square root of that.
  double tolerance = 1e-13;
  int max_iterations = 100;
  // Start from X = Z = I, y = 0 instead of CSDP's X = 10 alpha I, Z = 10 beta I, where alpha
  // grows with the total block size: for a problem scaled so that its solution's X, Z and y are
  // O(1), CSDP's start with 40 or more pose blocks is 1e3 times too large and it spends its
  // iterations walking back (lack of progress, or the iteration limit).
  bool identity_start = false;
};

struct LmiSolution {
  Eigen::VectorXd y;
  int code = -1;           // CSDP's return code: 0 solved, 3 solved with reduced accuracy, ...
  double objective = 0;    // b'y
  double lower_bound = 0;  // CSDP's primal objective tr(CX), a lower bound on b'y
  bool solved() const { return code == 0 || code == 3; }
  std::string message() const;
};

class LmiProblem {
 public:
  explicit LmiProblem(int variables);

  int variables() const { return static_cast<int>(objective_.size()); }
  int blocks() const { return static_cast<int>(constant_.size()); }

  // Adds a block with constant term F_k0 (square; only its symmetric part is used) and returns k.
  int add_block(const Eigen::MatrixXd& constant);
  // F_ki (same size as the block; symmetric part used; exact zeros are not stored). Each call
  // replaces an earlier one for the same (k, i).
  void set_coefficient(int block, int variable, const Eigen::MatrixXd& F);
  void set_objective(const Eigen::VectorXd& b);

  // Throws std::invalid_argument when a variable appears in no block (CSDP would exit()).
  // Serialized across threads: CSDP keeps a static work pointer in its Schur-complement routine.
  LmiSolution solve(const LmiSettings& settings = {}) const;

 private:
  struct Entry {
    int i, j;  // 1-based, i <= j
    double value;
  };
  std::vector<Eigen::MatrixXd> constant_;
  // coefficient_[variable][block]: the upper triangle of F_ki, row by row (CSDP's sorted order).
  std::vector<std::vector<std::vector<Entry>>> coefficient_;
  Eigen::VectorXd objective_;
};

}  // namespace symoro::identify::detail
