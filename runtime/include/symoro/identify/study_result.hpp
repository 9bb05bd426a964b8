// What the identification study produces (paper Algorithm 1 over every trajectory and
// interval, then PCA selection, rescue and validation): plain data, written by the study,
// saved per run, and read by the report.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::identify {

// One trajectory at one sampling interval: OLS -> audit -> (SDP) -> CLIE.
struct RunRecord {
  std::string trajectory;    // e.g. "AG02"
  double interval = 0;       // s
  int samples = 0;           // target-grid samples (rows of W are samples x joints)
  // OLS
  double kappa = 0;          // sigma_max / sigma_min of the stacked W (paper's kappa)
  double kappa_scaled = 0;   // the same with unit-norm columns (conditioning, not units)
  Eigen::VectorXd phi_ols, std_ols;  // estimate and standard deviations
  double residual_rms = 0;   // N m, of tau - W phi_ols
  bool weighted = false;     // WLS (per-joint weights) instead of OLS
  // All-pose audit of the OLS estimate
  double ols_lambda_min = 0;
  Eigen::VectorXd ols_worst_pose;
  bool ols_pd = false;
  // Conditional SDP projection
  std::string route;         // "O-C" or "O-S-C"
  double eps = 0;            // adopted margin, 0 when skipped
  bool sdp_feasible = true;  // false: no margin gave a PD projection (CLIE starts from the last)
  Eigen::VectorXd phi_sdp;   // the CLIE starting point (= phi_ols on O-C)
  // CLIE
  Eigen::VectorXd phi_clie;
  bool clie_success = false;
  std::string clie_termination;   // Ceres' termination, or the start's divergence
  double clie_cost_initial = 0, clie_cost_final = 0;
  int clie_iterations = 0;
  Eigen::VectorXd clie_rms;       // per joint, N m, at the samples
  double clie_lambda_min = 0;     // all-pose audit of phi_clie
  bool clie_pd = false;
  // Wall times, s
  double t_ols = 0, t_audit = 0, t_sdp = 0, t_clie = 0;

  std::string id() const;         // "AG02@40ms"
};

// The parameter clouds in one PCA basis (standardized parameters of all three stages).
struct PcaClouds {
  Eigen::VectorXd mean, scale;    // standardization: z = (phi - mean) / scale
  Eigen::MatrixXd components;     // np x k, orthonormal columns
  Eigen::VectorXd explained;      // fraction of variance per component
  Eigen::MatrixXd ols, sdp, clie; // runs x k scores
};

// Representative selection by centrality in the CLIE cloud.
struct Selection {
  int run = -1;                    // index into runs
  std::vector<double> centrality;  // per run: distance to the CLIE cloud's centre (smaller: central)
  int components = 0;              // PCA components used
  std::string rule;                // one line: how it was chosen
};

// Held-out validation of one trajectory: closed-loop simulated vs measured torque.
struct ValidationRecord {
  std::string trajectory;
  double interval = 0;
  double rmse_clie = 0, rmse_rescue = 0;   // N m, over all joints and samples
  double mne_clie = 0, mne_rescue = 0;     // mean over joints of |e_j| / |tau_m,j| (2-norms)
  Eigen::VectorXd rmse_joint_clie, rmse_joint_rescue;
  // The series (for the torque figure and the closed-loop localization): samples x joints; the
  // motion is the measured one, preprocessed like the torque.
  Eigen::VectorXd time;
  Eigen::MatrixXd q, qd, qdd;
  Eigen::MatrixXd tau_measured, tau_clie, tau_rescue;
};

struct StudyResult {
  std::string robot, model;               // robot and the identified model's variant
  std::vector<std::string> names, units;  // per parameter
  std::vector<RunRecord> runs;
  PcaClouds pca;
  Selection selection;
  // Post-CLIE rescue of the selected candidate and the final audit
  Eigen::VectorXd phi_rescue;
  bool rescued = false;                   // false: the CLIE candidate was PD, accepted as is
  double rescue_eps = 0;
  double final_lambda_min = 0;
  Eigen::VectorXd final_worst_pose;
  bool accepted = false;                  // final audit passed
  std::vector<ValidationRecord> validation;
  Eigen::VectorXd truth;                  // the twin's true parameters (empty for real data)
  std::string data_source;                // e.g. "twin (robots/crane_x7/twin.yaml, config ...)"
  int threads = 1;
  double wall = 0;                        // s, whole study (runs done in this invocation)
  double wall_runs = 0;                   // s, sum of the runs' stage times
};

}  // namespace symoro::identify
