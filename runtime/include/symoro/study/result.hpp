// What the identification study produces (paper Algorithm 1 over every trajectory and
// interval, then PCA selection, rescue and validation): plain data, written by the study,
// saved per run, and read by the report.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/study/prediction_uncertainty.hpp"

namespace symoro::study {

// One trajectory at one sampling interval: OLS -> audit -> (SDP) -> CLIE.
struct RunRecord {
  std::string trajectory;  // e.g. "AG02"
  // A run that could not be done (its log too short at this interval, a solver's exception):
  // recorded with the reason, left out of the clouds and the selection; the study goes on.
  bool failed = false;
  std::string failure;
  double interval = 0;  // s
  int samples = 0;      // target-grid samples (rows of W are samples x joints)
  // Target samples left out within the filter's settling time of a log end where the arm moves
  // (preprocess/edges.hpp); recorded only when there are some.
  int edge_samples = 0;
  // OLS
  double kappa = 0;         // sigma_max / sigma_min of the stacked W (paper's kappa)
  double kappa_scaled = 0;  // the same with unit-norm columns (conditioning, not units)
  // excitation/quality.hpp of W: log det of W'W with unit columns (<= 0) and the weakest
  // direction's largest components ("MX3 +0.71, MX2 -0.70, XXR4 -0.05")
  double log_det_scaled = 0;
  std::string weakest;
  Eigen::VectorXd phi_ols, std_ols;  // estimate and standard deviations
  double residual_rms = 0;           // N m, of tau - W phi_ols
  bool weighted = false;             // WLS (per-joint weights) instead of OLS
  // All-pose audit of the OLS estimate
  double ols_lambda_min = 0;
  Eigen::VectorXd ols_worst_pose;
  bool ols_pd = false;
  // Conditional SDP projection
  std::string route;         // "O-C" or "O-S-C"
  double eps = 0;            // adopted margin, 0 when skipped
  bool sdp_feasible = true;  // false: no margin gave a PD projection (CLIE starts from the last)
  Eigen::VectorXd phi_sdp;   // the CLIE starting point (= phi_ols on O-C)
  // CLIE. Without a controller description (or without reference columns in the log) CLIE
  // does not run: clie_ran is false, clie_termination says why, and phi_clie, clie_lambda_min
  // and clie_pd hold the run's final vector, the SDP (or, on O-C, the OLS) estimate, so that the
  // clouds, the selection and the rescue work on what the chain produced.
  bool clie_ran = true;
  Eigen::VectorXd phi_clie;
  bool clie_success = false;
  std::string clie_termination;  // Ceres' termination, or the start's divergence
  double clie_cost_initial = 0, clie_cost_final = 0;
  int clie_iterations = 0;
  Eigen::VectorXd clie_rms;    // per joint, N m, at the samples
  double clie_lambda_min = 0;  // all-pose audit of phi_clie
  bool clie_pd = false;
  // Consistency::physical only (physical = true): whether the OLS and CLIE vectors have a
  // physically consistent standard set, and phase 1's margin of each (relative to the links'
  // size; < 0: none; NaN: not needed, the prior's projection was consistent). route, eps (the
  // clearance) and sdp_feasible then describe the physical projection; the PD fields stay the
  // all-pose audit's.
  bool physical = false;
  bool ols_consistent = false, clie_consistent = false;
  double ols_consistency = std::numeric_limits<double>::quiet_NaN();
  double clie_consistency = std::numeric_limits<double>::quiet_NaN();
  // Wall times, s
  double t_ols = 0, t_audit = 0, t_sdp = 0, t_clie = 0;

  std::string id() const;  // "AG02@40ms"
};

// The parameter clouds in one PCA basis (standardized parameters of all three stages).
struct PcaClouds {
  Eigen::VectorXd mean, scale;     // standardization: z = (phi - mean) / scale
  Eigen::MatrixXd components;      // np x k, orthonormal columns
  Eigen::VectorXd explained;       // fraction of variance per component
  Eigen::MatrixXd ols, sdp, clie;  // runs x k scores
};

// Representative selection by centrality in the CLIE cloud.
struct Selection {
  int run = -1;                    // index into runs
  std::vector<double> centrality;  // per run: distance to the CLIE cloud's centre (smaller: central)
  int components = 0;              // PCA components used
  std::string rule;                // one line: how it was chosen
};

// Held-out validation of one trajectory: simulated vs measured torque. Closed loop (the model
// under the experiment's controller, the paper's Table VII) where a controller description and
// the log's references allow it; otherwise, or where that simulation diverges, open loop: the
// model's inverse dynamics on the measured motion against the measured torque.
struct ValidationRecord {
  std::string trajectory;
  std::string kind = "closed-loop";  // or "open-loop"
  std::string note;                  // why open loop, or where a simulation diverged ("" if neither)
  double interval = 0;
  int edge_samples = 0;  // as RunRecord's, of the held-out log at `interval`
  // Per joint rmse_j / rms(tau_m,j) of the accepted (rescue) vector: comparable across joints.
  Eigen::VectorXd nrmse_joint_rescue;
  double rmse_clie = 0, rmse_rescue = 0;  // N m, over all joints and samples
  double mne_clie = 0, mne_rescue = 0;    // mean over joints of |e_j| / |tau_m,j| (2-norms)
  Eigen::VectorXd rmse_joint_clie, rmse_joint_rescue;
  // Open loop against the raw measured torque at the log's own rate (raw_torque.hpp), beside the
  // filtered numbers above: what a plain least-squares fit would be compared with. NaN: not scored.
  double raw_rmse_clie = std::numeric_limits<double>::quiet_NaN(),
         raw_rmse_rescue = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd raw_rmse_joint_rescue;
  Eigen::VectorXd raw_floor_joint;  // the raw torque's content above the evaluation's cutoff (raw_torque.hpp)
  std::string raw_filter;           // the evaluation's own filter, one sentence
  // The accepted vector's 95 % prediction band (prediction_band.hpp) on this run, open loop: the
  // share of samples whose measured torque falls inside, over all joints and per joint (NaN: no
  // band), and the band's half-width per sample (samples x joints; for the figure).
  double band_coverage = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd band_coverage_joint;
  Eigen::MatrixXd tau_band;
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
  bool rescued = false;  // false: the CLIE candidate was PD, accepted as is
  double rescue_eps = 0;
  bool rescue_feasible = true;  // false: the rescue's projection failed (rescue_status says why)
  std::string rescue_status;
  // The physical rescue's prior weight, and when it was chosen by held-out error, each
  // candidate's open-loop RMSE on the other identification runs (N m).
  double rescue_prior_weight = 0;
  std::vector<std::pair<double, double>> rescue_prior_scores;
  std::string final_audit;  // its settings (acceptance.hpp's describe)
  double final_lambda_min = 0;
  Eigen::VectorXd final_worst_pose;
  // Final audit passed (physical: and a consistent set exists); acceptance_verdict
  // (acceptance.hpp) says why not.
  bool accepted = false;
  std::string consistency = "pd";  // the path: pd (the paper's) or physical
  // The logged torque's shift the parameters were identified with (s, preprocess::Options::
  // torque_delay): parameters.yaml's torque_delay_ms, which fits on top of them default to.
  double torque_delay = 0;
  // The accepted vector's physical consistency, checked on both paths where the model allows
  // (physical_projection.hpp): a consistent standard set maps onto it, phase 1's margin (NaN: not
  // needed), or why it was not checked.
  bool final_consistent = false;
  double final_consistency = std::numeric_limits<double>::quiet_NaN();
  std::string final_consistency_note;
  std::vector<ValidationRecord> validation;
  // The accepted vector's uncertainty on the selected run's samples (empty covariance: none).
  PredictionUncertainty uncertainty;
  Eigen::VectorXd truth;                       // the twin's true parameters (empty for real data)
  std::string data_source;                     // e.g. "twin (robots/crane_x7/twin.yaml, config ...)"
  std::string data_twin, data_twin_overrides;  // the dataset's twin and overrides ("" for real data)
  // What the chain did and skipped, one line each (e.g. "CLIE: not run: no controller
  // description (robots/x/controller.yaml)"), for the report.
  std::vector<std::string> stages;
  int threads = 1;  // worker threads per rank
  int ranks = 1;    // MPI ranks (1: this machine alone)
  // The largest peak resident memory of a trajectory's process (isolated runs; 0 otherwise) and
  // that trajectory: what one worker needs.
  double worker_peak_mb = 0;
  std::string worker_peak_trajectory;
  double wall = 0;       // s, whole study (runs done in this invocation)
  double wall_runs = 0;  // s, sum of the runs' stage times
};

}  // namespace symoro::study
