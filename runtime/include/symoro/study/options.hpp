// Every choice of the identification study, with the paper's values as defaults.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/study/acceptance.hpp"
#include "symoro/identify/clie.hpp"
#include "symoro/identify/least_squares.hpp"
#include "symoro/identify/pd_audit.hpp"
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/study/result.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::study {

// The metric of the SDP projections (pre-CLIE and the rescue): the paper's Euclidean distance
// in parameter space, or the run's information matrix W'W / sigma^2 (ridge-regularized), in
// which the projection changes the predicted torque as little as possible and moves mostly
// along the directions the data barely excites (docs/identification.md compares the two).
enum class ProjectionMetric { euclidean, information };
const char* to_string(ProjectionMetric m);
// "euclidean" or "information"; throws std::invalid_argument naming the choices otherwise.
ProjectionMetric projection_metric_from_string(const std::string& s);

// What makes a base vector admissible: the paper's all-pose PD of M(q) (sampled poses: the SDP
// projection's exchange loop and the audit), or a physically consistent standard set mapping
// onto it (per-link pseudo-inertia LMIs, IA, FV, FS >= 0: physical_projection.hpp), which implies
// M(q) > 0 at every pose and makes the accepted vector exportable (dynid export --urdf).
enum class Consistency { pd, physical };
const char* to_string(Consistency c);
// "pd" or "physical"; throws std::invalid_argument naming the choices otherwise.
Consistency consistency_from_string(const std::string& s);

struct StudyOptions {
  std::filesystem::path data;             // dataset folder (dataset.yaml and its logs)
  std::filesystem::path out;              // study folder: runs/ (one file per run) and the report
  int trial = 1;                          // which repetition of each trajectory
  std::vector<std::string> trajectories;  // identification set (empty: every family but V)
  std::vector<std::string> validation;    // held-out set (empty: family V)
  std::string validation_family = io::kHeldOutFamily;
  std::vector<double> intervals = preprocess::paper_intervals();
  int threads = 0;     // 0: every core
  bool fresh = false;  // redo every run, even those finished (benchmarks)
  // Each trajectory's runs in a process of their own (symoro/parallel/farm.hpp): a crash or an
  // out-of-memory kill fails those runs only, and every run starts from the same solver state,
  // so the records do not depend on the thread or rank count or on which runs went before.
  bool isolate = true;
  double rank_timeout = 60;  // s: MPI only (parallel::FarmOptions::rank_timeout)
  preprocess::Options preprocess;
  identify::LeastSquaresOptions least_squares;
  identify::AuditOptions audit;
  // The acceptance's final audit, relative to `audit` (acceptance.hpp). Not in describe(): no run
  // depends on it; the study applies it after the runs at every invocation and its result
  // records the settings it used (StudyResult::final_audit).
  FinalAuditOptions final_audit;
  // Its eps is set per margin. shortfall_raise 0.5: the exchange loop ends in about 2 rounds
  // instead of 6 for a distance larger by about 1e-4 (relative).
  identify::ProjectionOptions projection = [] {
    identify::ProjectionOptions p;
    p.shortfall_raise = 0.5;
    return p;
  }();
  std::vector<double> margins = identify::paper_margins();
  // The information metric: measured on the twin's 160-run study (docs/identification.md).
  ProjectionMetric projection_metric = ProjectionMetric::information;
  double information_ridge = 1e-9;  // times the information matrix's mean diagonal
  // Consistency::physical: the rescue is physical_projection (in the selected run's
  // predicted-torque metric W'W / rows, each link's pseudo-inertia clearing
  // physical_rescue_clearance of its size), acceptance needs a consistent set as well as the
  // final audit, and every run's OLS and final vectors are checked for one. CLIE starts where the
  // paper's does (the conditional PD projection) unless physical_start: then the OLS estimate is
  // projected onto the consistent set instead (clearance physical_clearance). Measured on the
  // twin's study (docs/identification.md): CLIE, unconstrained, walks back out of the consistent
  // set from such a start, in many more iterations, and some starts diverge.
  Consistency consistency = Consistency::pd;
  // The physical rescue's metric: the predicted torque on every identification trajectory at the
  // representative's interval (W'W / rows pooled), or on the representative's run alone (cheaper
  // to form, but free along what that one run barely excites: measured, docs/identification.md).
  bool rescue_metric_all_runs = true;
  bool physical_start = false;
  double physical_clearance = 1e-4;
  double physical_rescue_clearance = 1e-7;
  // The physical rescue's prior (standard parameters, e.g. the URDF's or CAD values; empty: zero)
  // and its relative weight: among the base vectors the torque metric barely tells apart, the
  // rescue takes the one whose standard set is nearest the prior (issue 30).
  Eigen::VectorXd rescue_prior;
  std::string rescue_prior_source;  // what it is, for the report
  double rescue_prior_weight = 1e-6;
  // When not empty, the weight is chosen among these by held-out error: each gives a rescued
  // vector, scored open loop on the identification runs other than the representative's (same
  // interval); the smallest error wins (the smaller weight on a tie within 0.1 %).
  std::vector<double> rescue_prior_weights;
  // Its preprocess options are the study's. Stopping rule of MATLAB's lsqnonlin (the paper's):
  // relative cost change 1e-6; at most 25 steps. Besides (ClieOptions' default): a parameter
  // that reaches its bound is held there (clie.hold_at_bounds; docs/identification.md: PB01 took
  // 22 steps for 0.02 % of cost); the noise-floor stop is off (clie.noise_floor 0, measured
  // there). No bounds by OLS standard deviations
  // (clie.std_bound 0): they also block CLIE's correction of OLS's bias, which can be many
  // sigma (docs/identification.md: FC2 moved 70 sigma, to the truth).
  identify::ClieOptions clie = [] {
    identify::ClieOptions c;
    c.function_tolerance = 1e-6;
    c.max_iterations = 25;
    return c;
  }();
  int pca_components = 5;
  double variance_fraction = 0.9;
  double validation_interval = 0;  // s; 0: the selected run's interval

  // Progress: the number of runs and of those already finished, then each new run as it ends.
  std::function<void(int total, int skipped)> on_start;
  std::function<void(const RunRecord&)> on_run;
  // Asked (on the coordinator, from any thread) before each trajectory's runs start: true stops
  // the study. The runs in progress finish and are saved, no other starts, and Study::run throws
  // StudyStopped on the coordinator (under MPI, the other ranks return); a rerun resumes.
  std::function<bool()> stop;

  // The options a run's result depends on, as text for its fingerprint.
  std::string describe() const;
};

}  // namespace symoro::study
