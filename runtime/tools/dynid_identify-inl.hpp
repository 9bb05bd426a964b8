// dynid identify's body for one model (included by the generated units only): the study on the
// dataset, printed, with its validation series and report written.
#pragma once

#include <algorithm>

#include <sys/resource.h>

#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "dynid_identify.hpp"
#include "symoro/control/description.hpp"
#include "symoro/identify/report.hpp"
#include "symoro/identify/study.hpp"
#include "symoro/identify/validation_io.hpp"
#include "symoro/parallel/farm.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::dynid {

namespace identify_detail {

template <class Full, class Model>
identify::StudyResult study(const Common& common, const IdentifyOptions& o, bool quiet) {
  identify::StudyOptions so;
  so.data = o.data;
  so.out = o.out;
  so.trial = o.trial;
  so.threads = o.threads;
  so.fresh = o.fresh;
  so.isolate = !o.in_process;
  so.rank_timeout = o.rank_timeout;
  so.trajectories = o.only;
  so.validation = o.validation;
  if (!o.intervals_ms.empty()) {
    so.intervals.clear();
    for (double ms : o.intervals_ms) so.intervals.push_back(ms / 1000);
  }
  so.least_squares.weighted = o.weighted;
  so.preprocess.torque_delay = o.torque_delay_ms / 1000;
  so.clie.max_iterations = o.clie_iterations;
  so.clie.std_bound = o.clie_std_bound;
  so.clie.noise_floor = o.clie_noise_floor;
  so.projection_metric = identify::projection_metric_from_string(o.projection_metric);
  so.consistency = identify::consistency_from_string(o.consistency);
  so.physical_start = o.physical_start;
  so.rescue_metric_all_runs = o.rescue_metric == "all";
  if (o.physical_start && so.consistency != identify::Consistency::physical)
    throw UsageError("--physical-start needs --consistency physical");
  so.validation_interval = o.validation_ms / 1000;
  auto progress = std::make_shared<std::unique_ptr<Progress>>();
  so.on_start = [progress, quiet](int total, int skipped) {
    if (skipped > 0) fmt::print(stderr, "{} of {} runs already finished (same inputs): skipped\n", skipped, total);
    if (!quiet) *progress = std::make_unique<Progress>(total - skipped, "run");
  };
  so.on_run = [progress](const identify::RunRecord& r) {
    if (*progress)
      (*progress)->done(r.id(), r.failed ? "FAILED: " + r.failure
                                : r.clie_ran ? fmt::format("kappa {:.1f} {} lambda_min(CLIE) {:+.2e} CLIE {:.1f} s", r.kappa, r.route,
                                                           r.clie_lambda_min, r.t_clie)
                                             : fmt::format("kappa {:.1f} {} lambda_min(final, no CLIE) {:+.2e}", r.kappa, r.route,
                                                           r.clie_lambda_min));
  };
  // What switches on the closed-loop stages: the robot's controller description (CLIE and
  // closed-loop validation) and its trajectory design (references for logs without them).
  const auto joints = joint_list<Model>();
  identify::ClosedLoopSource loop;
  const auto controller_path = common.robot_dir() / control::controller_file_name();
  if (std::filesystem::exists(controller_path))
    loop.setup = identify::closed_loop_setup(control::read_controller_description(controller_path, Model::nq));
  else
    loop.why = fmt::format("no controller description ({} not found)", controller_path.string());
  const auto design_path = common.robot_dir() / "trajectories.yaml";
  if (std::filesystem::exists(design_path)) loop.design = trajectory::TrajectoryDesign::read(design_path, joints);
  identify::Study<Model> s(so, std::move(loop));
  identify::StudyResult result = s.run();
  // On twin data the truth is known: the twin's standard parameters mapped to the identified
  // model's base parameters (products of inertia dropped for a reduced variant), with the hidden
  // Coulomb friction and offsets where the variant has parameters for them.
  const identify::Dataset data = identify::read_dataset(o.data);
  if (!data.twin.empty() && std::filesystem::exists(data.twin)) {
    const twin::TwinConfig tc = twin::read_twin_config(data.twin, Model::nq, data.twin_overrides);
    result.truth = twin::identified_truth<Model>(tc);
  }
  return result;
}

}  // namespace identify_detail

template <class Full, class Model>
void IdentifyCommand::run(const Common& common, const IdentifyOptions& o) {
  if (o.out.empty()) throw UsageError("--out is required");
  const identify::StudyResult r = identify_detail::study<Full, Model>(common, o, false);
  if (!parallel::place().coordinator()) return;  // rank 0 reports
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  fmt::print("{} runs, {}{} threads: {:.1f} s wall ({:.1f} s of run stages summed), peak memory {:.0f} MB{}\n", r.runs.size(),
             r.ranks > 1 ? fmt::format("{} ranks x ", r.ranks) : "", r.threads, r.wall, r.wall_runs, usage.ru_maxrss / 1024.0,
             r.worker_peak_mb > 0 ? fmt::format(" (this process), {:.0f} MB (a trajectory's process, largest: {})", r.worker_peak_mb,
                                                r.worker_peak_trajectory)
                                  : "");
  for (const auto& line : r.stages) fmt::print("{}\n", line);
  if (r.selection.run < 0) fmt::print("no representative: {}\n", r.selection.rule.empty() ? "no run produced a final vector" : r.selection.rule);
  if (r.selection.run >= 0) {
    const auto& sel = r.runs[r.selection.run];
    fmt::print("representative: {} ({}); {}; final audit lambda_min {:.3e} -> {}\n", sel.id(), r.selection.rule,
               r.rescued ? (r.rescue_feasible ? (r.consistency == "physical" ? "rescued onto the consistent set" : "rescued (eps = 0)")
                                                           : "rescue FAILED: " + r.rescue_status)
                         : (r.consistency == "physical" ? "consistent, no rescue" : "PD without rescue"),
               r.final_lambda_min, r.accepted ? "accepted" : "NOT accepted");
    fmt::print("physical consistency of the accepted vector: {}\n",
               r.final_consistency_note.empty() ? "not checked" : r.final_consistency_note);
    for (const auto& v : r.validation)
      fmt::print("validation {} at {:.0f} ms, {}: RMSE {:.4f} / {:.4f} N m, MNE {:.4f} / {:.4f} (final / accepted){}\n",
                 v.trajectory, v.interval * 1e3, v.kind, v.rmse_clie, v.rmse_rescue, v.mne_clie, v.mne_rescue,
                 v.note.empty() ? "" : "; " + v.note);
  }
  // The held-out series on disk: dynid compare reads them to set two model variants side by side.
  if (!identify::write_validation(r, o.out).empty())
    fmt::print("validation: {}\n", (std::filesystem::path(o.out) / "validation.yaml").string());
  if (!o.no_report) {
    const auto files = identify::write_report(r, std::filesystem::path(o.out) / "report");
    fmt::print("report: {} ({} files)\n", (std::filesystem::path(o.out) / "report" / "report.md").string(), files.size());
  }
  // A study without a model fails, after its records and report are written: `identify &&
  // export` must not carry on as if there were parameters.
  const auto failed = std::count_if(r.runs.begin(), r.runs.end(), [](const identify::RunRecord& run) { return run.failed; });
  if (r.runs.empty() || failed == static_cast<long>(r.runs.size()))
    throw std::runtime_error(fmt::format("no run of the study succeeded ({} of {} failed{}): no model was identified",
                                         failed, r.runs.size(),
                                         r.runs.empty() ? "" : "; the first: " + r.runs.front().id() + ": " + r.runs.front().failure));
  if (r.selection.run < 0)
    throw std::runtime_error(fmt::format("no representative run: {}; no model was identified",
                                         r.selection.rule.empty() ? "no run produced a final vector" : r.selection.rule));
}

}  // namespace symoro::dynid
