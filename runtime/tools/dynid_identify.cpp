// dynid identify: the whole identification study on a dataset (paper Algorithm 1 over every
// trajectory and interval, PCA selection, rescue, final audit, validation) and its report;
// resumable: finished runs are kept in <out>/runs/ and skipped by a rerun. --only and
// --interval narrow it to a few runs (e.g. --only AG02 --interval 40 to inspect one). Under
// mpirun the runs spread over the ranks and rank 0 writes the study (docs/scaling.md).
#include <optional>

#include <CLI/CLI.hpp>

#include "dynid_identify.hpp"
#include "dynid_numbers.hpp"
#include "symoro/io/folder_lock.hpp"
#include "symoro/parallel/farm.hpp"

namespace symoro::dynid {

void add_identify_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<IdentifyOptions>();
  auto* cmd = app.add_subcommand("identify", "Identification study on a dataset: OLS, PD audit, SDP, CLIE, PCA "
                                             "selection, rescue, validation, report");
  cmd->add_option("--robot", common.robot, "Robot folder name under robots/")->required();
  cmd->add_option("--robots-dir", common.robots_dir, "Where the robot folders are");
  cmd->add_option("--data", o->data, "Dataset folder (dataset.yaml and logs)")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--out", o->out, "Study folder (runs/ and report/)")->required();
  cmd->add_option("--model", o->model, "Model to identify: a robot.yaml variant, or full (default: robot.yaml's "
                                       "identified)");
  cmd->add_option("--interval", o->intervals_ms, "Sampling intervals in ms (default: 10 20 40 80)")->check(numbers::interval_ms());
  cmd->add_option("--only", o->only, "Identification trajectories (default: every family but V)")->delimiter(',');
  cmd->add_option("--validation", o->validation, "Validation trajectories (default: family V)")->delimiter(',');
  cmd->add_option("--trial", o->trial, "Which trial of each trajectory")->check(numbers::count(1, 1e6));
  cmd->add_option("-j,--jobs", o->threads, "Worker threads per rank (default: the cores, shared among the MPI ranks on "
                                            "a machine)")
      ->check(numbers::count(1, 1024));
  cmd->add_option("--rank-timeout", o->rank_timeout, "MPI: seconds of silence after which a rank is taken as lost and "
                                                    "its runs in flight fail (needs a launcher that keeps the job "
                                                    "alive, e.g. mpirun --mca orte_enable_recovery 1)")
      ->check(numbers::positive(1e6, "> 0 and <= 1e6 s"))
      ->capture_default_str();
  cmd->add_flag("--in-process", o->in_process, "Run the trajectories in threads of this process instead of a process "
                                               "each (for a debugger or a profiler; a crash then ends the study)");
  cmd->add_flag("--wls", o->weighted, "Weighted least squares (per-joint weights) instead of OLS");
  cmd->add_option("--torque-delay", o->torque_delay_ms, "ms the logged torque lags the links' (an actuation delay "
                                                        "dynid diagnose named): the torque is read that much later")
      ->check(numbers::checked(-1000, 1000, false, false, "from -1000 to 1000 ms"));
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
    identify_units().model(common, o->model)(common, *o);
  });
}

}  // namespace symoro::dynid
