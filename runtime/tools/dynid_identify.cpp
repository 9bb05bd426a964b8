// dynid identify: the whole identification study on a dataset (paper Algorithm 1 over every
// trajectory and interval, PCA selection, rescue, final audit, validation) and its report;
// resumable: finished runs are kept in <out>/runs/ and skipped by a rerun. --only and
// --interval narrow it to a few runs (e.g. --only AG02 --interval 40 to inspect one). Under
// mpirun the runs spread over the ranks and rank 0 writes the study (docs/scaling.md).
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dynid_identify.hpp"
#include "dynid_robots.hpp"
#include "dynid_numbers.hpp"
#include "symoro/identify/loaded_model.hpp"
#include "symoro/study/report.hpp"
#include "symoro/study/robot_folder.hpp"
#include "symoro/study/study.hpp"
#include "symoro/study/validation_io.hpp"
#include "symoro/io/folder_lock.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/parallel/farm.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::dynid {

namespace identify_detail {

study::StudyResult study(const Common& common, const IdentifyOptions& options, const robot::ModelHandle& handle,
                         const std::shared_ptr<const identify::IdentificationModel>& model, bool quiet) {
  const identify::ModelDescription& d = model->description();
  study::StudyOptions so;
  try {
    so = study::study_options(options, d, common.robot_dir());
  } catch (const study::StudyRequestError& e) {
    throw UsageError(e.what());
  }
  auto progress = std::make_shared<std::unique_ptr<Progress>>();
  so.on_start = [progress, quiet](int total, int skipped) {
    if (skipped > 0) fmt::print(stderr, "{} of {} runs already finished (same inputs): skipped\n", skipped, total);
    if (!quiet) *progress = std::make_unique<Progress>(total - skipped, "run");
  };
  so.on_run = [progress](const study::RunRecord& r) {
    if (*progress)
      (*progress)->done(r.id(), r.failed     ? "FAILED: " + r.failure
                                : r.clie_ran ? fmt::format("kappa {:.1f} {} lambda_min(CLIE) {:+.2e} CLIE {:.1f} s",
                                                           r.kappa, r.route, r.clie_lambda_min, r.t_clie)
                                             : fmt::format("kappa {:.1f} {} lambda_min(final, no CLIE) {:+.2e}",
                                                           r.kappa, r.route, r.clie_lambda_min));
  };
  // What switches on the closed-loop stages: the robot's controller description (CLIE and
  // closed-loop validation) and its trajectory design (references for logs without them).
  study::ClosedLoopSource loop = study::closed_loop_source(common.robot_dir(), d, common.design_path());
  study::Study s(model, so, std::move(loop));
  study::StudyResult result = s.run();
  // On twin data the truth is known: the twin's standard parameters mapped to the identified
  // model's base parameters (products of inertia dropped for a reduced variant), with the hidden
  // Coulomb friction and offsets where the variant has parameters for them.
  if (!result.data_twin.empty() && std::filesystem::exists(result.data_twin)) {
    const twin::TwinConfig tc = twin::read_twin_config(result.data_twin, d.nq, result.data_twin_overrides);
    result.truth = twin::identified_truth(handle, tc);
  }
  return result;
}

}  // namespace identify_detail

void run_identify(const Common& common, const IdentifyOptions& options) {
  if (options.out.empty()) throw UsageError("--out is required");
  const robot::ModelHandle handle = robot_model(common, options.model);
  const study::StudyResult r = identify_detail::study(
      common, options, handle, identify::identification_model(handle, full_model(common)), false);
  if (!parallel::place().coordinator()) return;  // rank 0 reports
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  fmt::print("{} runs, {}{} threads: {:.1f} s wall ({:.1f} s of run stages summed), peak memory {:.0f} MB{}\n",
             r.runs.size(), r.ranks > 1 ? fmt::format("{} ranks x ", r.ranks) : "", r.threads, r.wall, r.wall_runs,
             usage.ru_maxrss / 1024.0,
             r.worker_peak_mb > 0 ? fmt::format(" (this process), {:.0f} MB (a trajectory's process, largest: {})",
                                                r.worker_peak_mb, r.worker_peak_trajectory)
                                  : "");
  for (const auto& line : r.stages) fmt::print("{}\n", line);
  if (r.selection.run < 0)
    fmt::print("no representative: {}\n",
               r.selection.rule.empty() ? "no run produced a final vector" : r.selection.rule);
  if (r.selection.run >= 0) {
    const auto& sel = r.runs[r.selection.run];
    fmt::print("representative: {} ({}); {}; final audit lambda_min {:.3e} -> {}\n", sel.id(), r.selection.rule,
               r.rescued ? (r.rescue_feasible ? (r.consistency == "physical" ? "rescued onto the consistent set"
                                                                             : "rescued (eps = 0)")
                                              : "rescue FAILED: " + r.rescue_status)
                         : (r.consistency == "physical" ? "consistent, no rescue" : "PD without rescue"),
               r.final_lambda_min,
               r.accepted ? "accepted"
                          : fmt::format("NOT accepted: {}", fmt::join(study::acceptance_verdict(r).reasons, "; ")));
    fmt::print("physical consistency of the accepted vector: {}\n",
               r.final_consistency_note.empty() ? "not checked" : r.final_consistency_note);
    for (const auto& v : r.validation) {
      fmt::print("validation {} at {:.0f} ms, {}: RMSE {:.4f} / {:.4f} N m, MNE {:.4f} / {:.4f} (final / accepted){}\n",
                 v.trajectory, v.interval * 1e3, v.kind, v.rmse_clie, v.rmse_rescue, v.mne_clie, v.mne_rescue,
                 v.note.empty() ? "" : "; " + v.note);
      if (std::isfinite(v.raw_rmse_rescue))
        fmt::print(
            "validation {} against the raw torque, open loop: RMSE {:.4f} / {:.4f} N m (final / accepted), mean of the "
            "joints' RMSE {:.4f} N m (accepted); the torque's own content above the evaluation's cutoff, which no "
            "model of the filtered motion follows: {:.4f} N m (mean of the joints)\n",
            v.trajectory, v.raw_rmse_clie, v.raw_rmse_rescue,
            v.raw_rmse_joint_rescue.size() > 0 ? v.raw_rmse_joint_rescue.mean() : std::nan(""),
            v.raw_floor_joint.size() > 0 ? v.raw_floor_joint.mean() : std::nan(""));
    }
  }
  // The held-out series on disk: dynid compare reads them to set two model variants side by side.
  if (!study::write_validation(r, options.out).empty())
    fmt::print("validation: {}\n", (std::filesystem::path(options.out) / "validation.yaml").string());
  if (!options.no_report) {
    const auto files = study::write_report(r, std::filesystem::path(options.out) / "report");
    fmt::print("report: {} ({} files)\n", (std::filesystem::path(options.out) / "report" / "report.md").string(),
               files.size());
  }
  // A study without a model fails, after its records and report are written: `identify &&
  // export` must not carry on as if there were parameters.
  study::require_identified(r);
}

void add_identify_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<IdentifyOptions>();
  auto* cmd = app.add_subcommand("identify",
                                 "Identification study on a dataset: OLS, PD audit, SDP, CLIE, PCA "
                                 "selection, rescue, validation, report");
  add_robot_options(cmd, common);
  cmd->add_option("--design", common.design,
                  "A trajectory design file (e.g. dynid excite's) instead of robots/<robot>/trajectories.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_option("--data", o->data, "Dataset folder (dataset.yaml and logs)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--out", o->out, "Study folder (runs/ and report/)")->required();
  cmd->add_option("--model", o->model,
                  "Model to identify: a robot.yaml variant, or full (default: robot.yaml's "
                  "identified)");
  cmd->add_option("--interval", o->intervals_ms, "Sampling intervals in ms (default: 10 20 40 80)")
      ->check(numbers::interval_ms());
  cmd->add_option("--only", o->only, "Identification trajectories (default: every family but V)")->delimiter(',');
  cmd->add_option("--validation", o->validation, "Validation trajectories (default: family V)")->delimiter(',');
  cmd->add_option("--trial", o->trial, "Which trial of each trajectory")->check(numbers::count(1, 1e6));
  cmd->add_option("-j,--jobs", o->threads,
                  "Worker threads per rank (default: the cores, shared among the MPI ranks on "
                  "a machine)")
      ->check(numbers::count(1, 1024));
  cmd->add_option("--rank-timeout", o->rank_timeout,
                  "MPI: seconds of silence after which a rank is taken as lost and "
                  "its runs in flight fail (needs a launcher that keeps the job "
                  "alive, e.g. mpirun --mca orte_enable_recovery 1)")
      ->check(numbers::positive(1e6, "> 0 and <= 1e6 s"))
      ->capture_default_str();
  cmd->add_flag("--in-process", o->in_process,
                "Run the trajectories in threads of this process instead of a process "
                "each (for a debugger or a profiler; a crash then ends the study)");
  cmd->add_flag("--wls", o->weighted, "Weighted least squares (per-joint weights) instead of OLS");
  cmd->add_option("--torque-delay", o->torque_delay_ms,
                  "ms the logged torque lags the links' (an actuation delay "
                  "dynid diagnose named): the torque is read that much later")
      ->check(numbers::checked(-1000, 1000, false, false, "from -1000 to 1000 ms"));
  cmd->add_flag("--logged-velocity", o->logged_velocity,
                "Fit on the log's velocity column instead of q's zero-phase "
                "derivative (the log must have one; its lag is the controller's)");
  cmd->add_option("--clie-iterations", o->clie_iterations, "CLIE iteration limit")->check(numbers::count(0, 100000));
  cmd->add_option("--projection-metric", o->projection_metric,
                  "Metric of the SDP projection and the rescue: euclidean (the paper's) or information (the run's "
                  "W'W: the smallest change of the predicted torque)")
      ->check(CLI::IsMember({"euclidean", "information"}))
      ->capture_default_str();
  cmd->add_option("--consistency", o->consistency,
                  "What makes a parameter vector admissible: pd (the paper's: M(q) positive definite at every pose, "
                  "sampled) or physical (also a physically consistent set of link inertials maps onto it: per-link "
                  "LMIs; the rescue projects onto such vectors, and dynid export --urdf reproduces the accepted one "
                  "exactly)")
      ->check(CLI::IsMember({"pd", "physical"}))
      ->capture_default_str();
  cmd->add_option("--rescue-metric", o->rescue_metric,
                  "With --consistency physical: the rescue moves the representative onto the consistent set changing "
                  "least the torque predicted on all the identification trajectories (all) or on its own run (run)")
      ->check(CLI::IsMember({"all", "run"}))
      ->capture_default_str();
  cmd->add_option(
      "--rescue-prior", o->rescue_prior,
      "With --consistency physical: the standard parameters the rescue leans towards along what the data "
      "barely tell apart: nominal (robot.yaml's), zero, or a standard-parameter YAML (default: robot.yaml's "
      "nominal when it has them, else zero)");
  cmd->add_option("--rescue-prior-weight", o->rescue_prior_weight, "The prior's weight relative to the torque metric")
      ->check(numbers::positive(1e6, "> 0 and <= 1e6"))
      ->capture_default_str();
  cmd->add_option("--rescue-prior-weights", o->rescue_prior_weights,
                  "Weights to choose the prior's among by held-out error (comma-separated, e.g. 1e-6,1e-4,1e-2): each "
                  "rescue is scored open loop on the identification runs other than the representative's")
      ->delimiter(',')
      ->check(numbers::positive(1e6, "> 0 and <= 1e6"));
  cmd->add_flag("--physical-start", o->physical_start,
                "With --consistency physical: project each OLS estimate onto the consistent set before CLIE instead "
                "of the paper's PD projection (slower: CLIE walks back out of the set; docs/identification.md)");
  cmd->add_option("--clie-std-bound", o->clie_std_bound,
                  "CLIE bounds of +-K standard deviations of the run's OLS estimate around its start (0: off)")
      ->check(numbers::non_negative(1e6, ">= 0 and <= 1e6"))
      ->capture_default_str();
  cmd->add_option("--clie-noise-floor", o->clie_noise_floor,
                  "CLIE also stops when a step lowers its cost by less than this many residual variances "
                  "(2 cost / (residuals - parameters)); 0.5: a step shorter than one standard deviation of the "
                  "estimate; 0 (default): the paper's relative tolerance 1e-6 alone (0.5 stopped some runs early: "
                  "docs/identification.md)")
      ->check(numbers::non_negative(1e6, ">= 0 and <= 1e6"))
      ->capture_default_str();
  cmd->add_option("--validation-interval", o->validation_ms, "Validation interval in ms (default: the selected run's)")
      ->check(numbers::interval_ms());
  cmd->add_flag("--no-report", o->no_report, "Do not write the report");
  cmd->add_flag("--fresh", o->fresh, "Redo every run, even finished ones (to time the whole study)");
  cmd->callback([&common, o] {
    // One study per folder at a time (rank 0 writes it; the other ranks only compute).
    std::optional<io::FolderLock> lock;
    if (!o->out.empty() && parallel::place().coordinator()) lock.emplace(o->out, "dynid identify");
    run_identify(common, *o);
  });
}

}  // namespace symoro::dynid
