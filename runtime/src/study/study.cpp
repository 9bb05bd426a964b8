// The identification study (study.hpp) for any model, through its IdentificationModel: compiled
// once for every robot.
#include "symoro/study/study.hpp"

#include "symoro/study/prediction_band.hpp"

#include "symoro/study/raw_torque.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "symoro/error.hpp"
#include "symoro/study/acceptance.hpp"
#include "symoro/identify/clie.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/identify/least_squares.hpp"
#include "pca.hpp"
#include "symoro/identify/pd_audit.hpp"
#include "symoro/identify/physical_projection.hpp"
#include "symoro/study/run_record_io.hpp"
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/study/detail/run.hpp"
#include "symoro/study/validation.hpp"
#include "symoro/io/digest.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/text_file.hpp"
#include "symoro/parallel/farm.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/trajectory/sampled_reference.hpp"

namespace symoro::study {
namespace {

using io::Dataset;
using io::DatasetRun;

// One study's run: the model, options and closed loop it works with, and what it builds once.
class StudyRun {
 public:
  StudyRun(const identify::IdentificationModel& model, const StudyOptions& options, const ClosedLoopSource& closed_loop)
      : model_(model),
        d_(model.description()),
        o_(options),
        loop_(closed_loop),
        inertia_(model.inertia_function()),
        domain_(identify::audit_domain(d_.joints)) {}

  StudyResult run() {
    const auto t0 = std::chrono::steady_clock::now();
    if (o_.consistency == Consistency::physical && !model_.supports_physical_consistency())
      throw std::invalid_argument(fmt::format("--consistency physical: {}; identify it with the PD path",
                                              model_.physical_check(Eigen::VectorXd::Zero(d_.np)).message));
    const Dataset data = io::read_dataset(o_.data);
    io::check_dataset_robot(data, d_.robot);
    StudyResult out = described(data);
    const std::vector<std::string> ident = identification_names(data), valid = validation_names(data);

    std::vector<Slot> slots = planned_runs(data, ident);
    const parallel::FarmSummary farmed = farm_runs(data, ident, slots, out);
    out.threads = farmed.workers;
    out.ranks = farmed.ranks;
    if (!parallel::place().coordinator()) return out;  // rank 0 gathers the records and goes on

    for (Slot& s : slots) out.runs.push_back(std::move(*s.record));
    int failures = 0;
    for (const RunRecord& r : out.runs) {
      out.wall_runs += r.t_ols + r.t_audit + r.t_sdp + r.t_clie;
      failures += r.failed;
    }
    describe_stages(out, failures);

    select_and_accept(data, out);
    if (out.selection.run >= 0) validate(data, valid, out);
    out.wall = detail::seconds_since(t0);
    return out;
  }

 private:
  // A run of the study: a trajectory at an interval, its record file and fingerprint, and its
  // record once finished (loaded when a finished run's fingerprint matches).
  struct Slot {
    std::string trajectory;
    double interval;
    std::filesystem::path file;
    std::string fingerprint;
    std::optional<RunRecord> record;
  };

  // The result's description of the study: robot, model, parameters, the data's source.
  StudyResult described(const Dataset& data) const {
    StudyResult out;
    out.robot = d_.robot;
    out.model = d_.variant;
    out.consistency = to_string(o_.consistency);
    out.torque_delay = o_.preprocess.torque_delay;
    for (const auto& p : d_.parameters) {
      out.names.push_back(p.name);
      out.units.push_back(p.unit);
    }
    out.data_twin = data.twin;
    out.data_twin_overrides = data.twin_overrides;
    out.data_source = data.twin.empty() ? "measured (" + data.dir.string() + ")"
                                        : "digital twin (" + data.twin + "), " + data.dir.string();
    return out;
  }

  // Every run's fingerprint; finished runs are loaded, the others are left to do.
  std::vector<Slot> planned_runs(const Dataset& data, const std::vector<std::string>& ident) {
    std::filesystem::create_directories(o_.out / "runs");
    std::vector<Slot> slots;
    const StudyInputs inputs = study_inputs();  // once: the design file is read for its hash
    for (const auto& name : ident) {
      const DatasetRun& run = data.find(name, o_.trial);
      const io::LogMetadata meta = io::read_log_metadata(run.file);
      const std::string content = log_digest(run);  // once per log, whatever the intervals
      for (double h : o_.intervals) {
        Slot s{name, h, o_.out / "runs" / fmt::format("{}@{}ms.yaml", name, std::lround(h * 1e3)), {}, {}};
        s.fingerprint = fingerprint_of(run_inputs(inputs, run, meta, content, h));
        if (!o_.fresh) s.record = load_run(s.file, s.fingerprint);
        slots.push_back(std::move(s));
      }
    }
    return slots;
  }

  // The runs left to do, one task per trajectory (its log read once, its missing intervals in
  // order), on the farm: this machine's threads, or MPI ranks when started by mpirun. Each
  // record is saved as it comes; a stopped study throws StudyStopped with what is saved.
  parallel::FarmSummary farm_runs(const Dataset& data, const std::vector<std::string>& ident, std::vector<Slot>& slots,
                                  StudyResult& out) {
    std::vector<std::string> todo;
    for (const auto& name : ident)
      for (const Slot& s : slots)
        if (s.trajectory == name && !s.record) {
          todo.push_back(name);
          break;
        }
    // Longest first (the log's size stands for its duration), so no thread ends on a long one.
    std::stable_sort(todo.begin(), todo.end(), [&](const std::string& a, const std::string& b) {
      return std::filesystem::file_size(data.find(a, o_.trial).file) >
             std::filesystem::file_size(data.find(b, o_.trial).file);
    });
    const int skipped =
        static_cast<int>(std::count_if(slots.begin(), slots.end(), [](const Slot& s) { return s.record.has_value(); }));
    if (o_.on_start && parallel::place().coordinator()) o_.on_start(static_cast<int>(slots.size()), skipped);

    // One task per trajectory (its log read once, its missing intervals in order), on the
    // farm: this machine's threads, or MPI ranks when started by mpirun.
    std::vector<std::string> tasks;
    for (const auto& name : todo) {
      std::string task = name;
      for (const Slot& s : slots)
        if (s.trajectory == name && !s.record) task += fmt::format("\n{:.17g}", s.interval);  // 17 digits: exact
      tasks.push_back(std::move(task));
    }
    auto failed = [](const std::string& trajectory, double interval, const std::string& why) {
      RunRecord r;
      r.trajectory = trajectory;
      r.interval = interval;
      r.failed = true;
      r.failure = why;
      return r;
    };
    auto finish = [&](Slot& s, RunRecord r) {
      if (!r.failed) save_run(r, s.fingerprint, s.file);  // a failed run is tried again by a rerun
      s.record = std::move(r);
      if (o_.on_run) o_.on_run(*s.record);
    };
    parallel::Farm farm;
    farm.work = [&](const std::string& task, const std::function<void(const std::string&)>& emit) {
      std::istringstream in(task);
      std::string name, line;
      std::getline(in, name);
      const io::Log log = load_log(data.find(name, o_.trial));
      std::string no_clie;
      const auto sim = closed_loop(name, log, no_clie);
      while (std::getline(in, line)) {
        const double h = std::stod(line);
        RunRecord r;
        try {
          r = detail::identify_run(model_, log, sim.get(), no_clie, h, o_, *inertia_, domain_);
        } catch (const std::exception& e) {
          r = failed(name, h, e.what());
        }
        emit(run_record_text(r, ""));
      }
    };
    farm.on_result = [&](std::size_t, const std::string& text) {
      RunRecord r = run_record_from_text(text);
      for (Slot& s : slots)
        if (!s.record && s.trajectory == r.trajectory && s.interval == r.interval) return finish(s, std::move(r));
    };
    farm.on_end = [&](const parallel::TaskEnd& e) {
      const std::string& name = todo[e.task];
      if (e.peak_memory_mb > out.worker_peak_mb) {
        out.worker_peak_mb = e.peak_memory_mb;
        out.worker_peak_trajectory = name;
      }
      if (!e.failed) return;
      for (Slot& s : slots)  // the runs the task did not finish
        if (s.trajectory == name && !s.record) finish(s, failed(s.trajectory, s.interval, e.failure));
    };
    farm.stop = o_.stop;
    parallel::FarmOptions fo;
    fo.workers = o_.threads;
    fo.isolate = o_.isolate;
    fo.rank_timeout = o_.rank_timeout;
    const parallel::FarmSummary farmed = parallel::run_farm(tasks, farm, fo);
    if (farmed.stopped) {
      const auto saved =
          std::count_if(slots.begin(), slots.end(), [](const Slot& s) { return s.record && !s.record->failed; });
      throw StudyStopped(fmt::format("the study was stopped: {} of {} runs are saved in {}; run it again to resume",
                                     saved, slots.size(), (o_.out / "runs").string()));
    }
    return farmed;
  }

  // Names in order, each once: a repeated name would give one run to two threads.
  static std::vector<std::string> unique(const std::vector<std::string>& names) {
    std::vector<std::string> v;
    for (const auto& n : names)
      if (std::find(v.begin(), v.end(), n) == v.end()) v.push_back(n);
    return v;
  }
  std::vector<std::string> identification_names(const Dataset& d) const {
    if (!o_.trajectories.empty()) return unique(o_.trajectories);
    std::vector<std::string> v;
    for (const DatasetRun& r : d.runs)
      if (r.trial == o_.trial && r.family != o_.validation_family) v.push_back(r.trajectory);
    return unique(v);
  }
  std::vector<std::string> validation_names(const Dataset& d) const {
    if (!o_.validation.empty()) return unique(o_.validation);
    std::vector<std::string> v;
    for (const DatasetRun& r : d.runs)
      if (r.trial == o_.trial && r.family == o_.validation_family) v.push_back(r.trajectory);
    return unique(v);
  }

  // A run's log, its time counted from its first stamp (a controller's log may start at any t;
  // the closed loop's cycle 0 is the first row).
  io::Log load_log(const DatasetRun& run) const {
    io::Log log = io::read_run_log(run, d_.robot, d_.nq);
    if (log.samples() > 0) log.time.array() -= log.time(0);
    return log;
  }

  // The closed loop of one run, or nullptr with the reason: the log's reference columns first,
  // else the design's trajectory of that name.
  std::unique_ptr<identify::ClosedLoop> closed_loop(const std::string& name, const io::Log& log,
                                                    std::string& why) const {
    if (!loop_.setup) {
      why = loop_.why.empty() ? "no controller description" : loop_.why;
      return nullptr;
    }
    if (log.has_references())
      return model_.closed_loop(*loop_.setup, trajectory::sampled_reference(log, loop_.setup->gains.period));
    if (loop_.design) {
      const auto names = loop_.design->names();
      if (std::find(names.begin(), names.end(), name) != names.end())
        return model_.closed_loop(*loop_.setup,
                                  trajectory::sample(loop_.design->build(name), loop_.setup->gains.period));
    }
    why = fmt::format("the log of {} has no reference columns{}", name,
                      loop_.design ? " and the trajectory design has no trajectory of that name"
                                   : " and the robot has no trajectory design");
    return nullptr;
  }

  void describe_stages(StudyResult& out, int failures) const {
    int clie = 0, skipped = 0;
    std::string why;
    for (const RunRecord& r : out.runs) {
      if (r.failed) continue;
      if (r.clie_ran) {
        ++clie;
      } else {
        ++skipped;
        if (why.empty()) why = r.clie_termination;
      }
    }
    out.stages.push_back(fmt::format("OLS{}, all-pose PD audit, conditional SDP projection: {} runs",
                                     o_.least_squares.weighted ? " (WLS)" : "", out.runs.size() - failures));
    if (o_.consistency == Consistency::physical)
      out.stages.push_back(fmt::format(
          "physical consistency (per-link pseudo-inertia LMIs, IA, FV, FS >= 0): every run's OLS and final vectors "
          "checked; {}the rescue onto the base vectors with a consistent standard set in the metric of the torque "
          "predicted on {} (clearance {:g} of each link's size), leaning along what that metric barely sees towards "
          "{} (weight {}); acceptance needs a consistent set and the final audit",
          o_.physical_start ? fmt::format("CLIE's start projected onto that set (clearance {:g}) instead of the PD "
                                          "projection; ",
                                          o_.physical_clearance)
                            : "CLIE's start the paper's (conditional PD projection); ",
          o_.rescue_metric_all_runs ? "every identification trajectory at the representative's interval"
                                    : "the representative's run",
          o_.physical_rescue_clearance,
          o_.rescue_prior.size() > 0 ? o_.rescue_prior_source
                                     : std::string("zero inertia (no prior: the links shrink towards line-like "
                                                   "mass distributions; give --rescue-prior)"),
          o_.rescue_prior_weights.empty() ? fmt::format("{:g}", o_.rescue_prior_weight)
                                          : "chosen by held-out error, below"));
    if (o_.consistency == Consistency::pd || !o_.physical_start)
      out.stages.push_back(
          fmt::format("SDP projection{} in the {} metric{}", o_.consistency == Consistency::pd ? " and rescue" : "",
                      to_string(o_.projection_metric),
                      o_.projection_metric == ProjectionMetric::information ? " (the run's W'W / sigma^2)" : ""));
    const std::string bounds =
        o_.clie.std_bound > 0
            ? fmt::format(" (bounds: +-{:g} OLS standard deviations around the start)", o_.clie.std_bound)
            : "";
    if (skipped == 0)
      out.stages.push_back(fmt::format("CLIE: {} runs{}", clie, bounds));
    else
      out.stages.push_back(fmt::format("CLIE: {} runs; skipped in {} ({}){}", clie, skipped, why,
                                       clie == 0 ? "; each run's final vector is its SDP (or PD OLS) estimate" : ""));
    if (failures > 0) {
      std::string list;
      for (const RunRecord& r : out.runs)
        if (r.failed) list += fmt::format("{}{}: {}", list.empty() ? "" : "; ", r.id(), r.failure);
      out.stages.push_back(fmt::format("failed runs: {} ({})", failures, list));
    }
  }

  // What a run's result depends on: the model, the log (the digest of every byte read: its CSV
  // and its sidecar; one value edited in place is another log), the window, the interval, every option of every stage
  // and the closed loop (controller and the design's file, when given). The parts shared by
  // every run are made once per study.
  struct StudyInputs {
    std::string model, loop;
  };
  StudyInputs study_inputs() const {
    StudyInputs in;
    // The compiled model: its parameters and joints (a regenerated model with other names or
    // limits is another model).
    in.model = fmt::format("{}/{} ", d_.robot, d_.variant);
    for (const auto& p : d_.parameters) in.model += std::string(p.name) + " ";
    for (const auto& j : d_.joints) in.model += fmt::format("{} {} {} ", j.name, j.lower, j.upper);
    in.loop = "open";
    if (loop_.setup) {
      const identify::ClosedLoopSetup& c = *loop_.setup;
      in.loop = fmt::format("{} {} {} {} {} | {} {} {} {}", c.gains.period, c.gains.pseudo_derivative_time, c.delay,
                            c.pre_roll, c.substeps, fmt::join(c.gains.inertia, " "), fmt::join(c.gains.damping, " "),
                            fmt::join(c.gains.kp, " "), fmt::join(c.gains.kv, " "));
      // The design's bytes (an unreadable design is an error, not an empty fingerprint).
      if (loop_.design)
        in.loop +=
            " | " + fingerprint_of(io::read_text_file(loop_.design->path(), "cannot read the trajectory design"));
    }
    return in;
  }
  static std::string log_digest(const DatasetRun& run) {
    std::string d = io::file_digest(run.file);
    const auto sidecar = io::metadata_path(run.file);
    if (std::filesystem::exists(sidecar)) d += " " + io::file_digest(sidecar);
    return d;
  }
  std::string run_inputs(const StudyInputs& in, const DatasetRun& run, const io::LogMetadata& meta,
                         const std::string& content, double interval) const {
    return fmt::format("{}| {} {} {} {} {} [{}, {}] | {} | {} | {}", in.model, run.file.filename().string(), content,
                       meta.seed, meta.notes, meta.trial, run.window_start, run.window_end, interval, o_.describe(),
                       in.loop);
  }

  // A run's least squares again (the rescue's metric: its information matrix).
  identify::LeastSquaresResult refit(const Dataset& data, const RunRecord& r) const {
    const preprocess::Samples s =
        preprocess::preprocess(load_log(data.find(r.trajectory, o_.trial)), r.interval, o_.preprocess);
    return least_squares(model_.stack_regression(s), o_.least_squares);
  }

  // W'W / rows over every identification trajectory at one interval (ridge-regularized like the
  // information metric): distances in it are RMS changes of the torque predicted on all the
  // identification data. A log too short for the interval is left out.
  Eigen::MatrixXd pooled_torque_metric(const Dataset& data, double interval) const {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(d_.np, d_.np);
    double rows = 0;
    for (const auto& name : identification_names(data)) {
      try {
        const preprocess::Samples s =
            preprocess::preprocess(load_log(data.find(name, o_.trial)), interval, o_.preprocess);
        const identify::Regression reg = model_.stack_regression(s);
        A.selfadjointView<Eigen::Lower>().rankUpdate(reg.W.transpose());
        rows += static_cast<double>(reg.W.rows());
      } catch (const std::exception&) {
        continue;
      }
    }
    if (rows == 0)
      throw std::runtime_error("the rescue's metric: no identification log could be read at this interval");
    A = A.selfadjointView<Eigen::Lower>();
    return identify::information_metric(A / rows, o_.information_ridge);
  }

  // The acceptance rule (acceptance.hpp): the representative, its rescue when its vector is not
  // admissible on the study's path, the final audit, the verdict.
  void select_and_accept(const Dataset& data, StudyResult& out) const {
    std::optional<Representative> rep = select_representative(out.runs, o_.pca_components, o_.variance_fraction);
    if (!rep) return;  // no run produced a final vector
    out.pca = std::move(rep->pca);
    out.selection = std::move(rep->selection);
    if (out.selection.run < 0) return;
    const RunRecord& sel = out.runs[out.selection.run];
    out.phi_rescue = sel.phi_clie;
    out.rescued = false;
    if (o_.consistency == Consistency::physical && !sel.clie_consistent) rescue_physical(data, sel, out);
    if (o_.consistency == Consistency::pd && !sel.clie_pd) rescue_pd(data, sel, out);
    final_audit(out);
  }

  // The rescue over standard parameters: the nearest base vector with a consistent set, in the
  // predicted-torque metric, towards the prior (its weight chosen by held-out error when several).
  void rescue_physical(const Dataset& data, const RunRecord& sel, StudyResult& out) const {
    const Eigen::MatrixXd metric = o_.rescue_metric_all_runs
                                       ? pooled_torque_metric(data, sel.interval)
                                       : detail::torque_metric(refit(data, sel), o_.information_ridge);
    auto rescue = [&](double weight) {
      return model_.physical_projection(sel.phi_clie, metric, o_.physical_rescue_clearance, o_.rescue_prior, weight);
    };
    out.rescue_prior_weight = o_.rescue_prior_weight;
    identify::PhysicalProjection p;
    if (o_.rescue_prior_weights.empty()) {
      p = rescue(o_.rescue_prior_weight);
    } else {
      const std::vector<preprocess::Samples> others = other_runs_at_interval(data, sel, out);
      const auto heldout_rmse = [&](const Eigen::VectorXd& phi) {
        double sq = 0, count = 0;
        for (const auto& s : others) {
          const Eigen::MatrixXd e = s.tau - model_.open_loop_torque(s, phi);
          sq += e.squaredNorm();
          count += static_cast<double>(e.size());
        }
        return count > 0 ? std::sqrt(sq / count) : 0.0;
      };
      PriorWeightChoice choice =
          choose_prior_weight(o_.rescue_prior_weights, o_.rescue_prior_weight, rescue, heldout_rmse);
      p = std::move(choice.projection);
      out.rescue_prior_weight = choice.weight;
      out.rescue_prior_scores = choice.scores;
      std::string scores;
      for (const auto& [w, e] : out.rescue_prior_scores)
        scores += fmt::format("{}{:g}: {:.6g}", scores.empty() ? "" : ", ", w, e);
      out.stages.push_back(
          fmt::format("rescue prior weight: {:g}, by held-out open-loop RMSE on {} other runs (N m; {})",
                      out.rescue_prior_weight, others.size(), scores));
    }
    out.phi_rescue = p.phi;
    out.rescued = true;
    out.rescue_eps = o_.physical_rescue_clearance;
    out.rescue_feasible = p.feasible;
    out.rescue_status = p.status;
  }

  // Held out for the prior's weight: the other identification runs at the representative's
  // interval, preprocessed (a log that cannot be read is left out).
  std::vector<preprocess::Samples> other_runs_at_interval(const Dataset& data, const RunRecord& sel,
                                                          const StudyResult& out) const {
    std::vector<preprocess::Samples> others;
    for (const RunRecord& r : out.runs)
      if (&r != &sel && !r.failed && std::abs(r.interval - sel.interval) < 1e-12) {
        try {
          others.push_back(
              preprocess::preprocess(load_log(data.find(r.trajectory, o_.trial)), r.interval, o_.preprocess));
        } catch (const std::exception&) {
        }
      }
    return others;
  }

  // The paper's rescue: a minimal feasibility correction onto the all-pose PD set (eps 0).
  void rescue_pd(const Dataset& data, const RunRecord& sel, StudyResult& out) const {
    identify::ProjectionOptions po = o_.projection;
    po.eps = 0;
    if (o_.projection_metric == ProjectionMetric::information)
      po.metric = identify::information_metric(refit(data, sel).information, o_.information_ridge);
    const identify::ProjectionResult p = project_pd(*inertia_, sel.phi_clie, domain_, po);
    out.phi_rescue = p.phi;
    out.rescued = true;
    out.rescue_eps = 0;
    out.rescue_feasible = p.feasible;
    out.rescue_status = p.status;
  }

  // The final audit (denser, poses the pipeline never saw), the accepted vector's physical
  // consistency on both paths, and the verdict.
  void final_audit(StudyResult& out) const {
    const identify::AuditOptions fa = final_audit_options(o_.audit, o_.final_audit);
    out.final_audit = describe(fa);
    const identify::AuditResult a = audit_pd(*inertia_, out.phi_rescue, domain_, fa);
    out.final_lambda_min = a.lambda_min;
    out.final_worst_pose = a.worst_pose;
    const identify::ConsistencyResult k = model_.physical_check(out.phi_rescue);
    out.final_consistent = k.ok();
    out.final_consistency = k.feasibility;
    out.final_consistency_note = k.message;
    out.accepted = acceptance_verdict(out).accepted;
  }

  void validate(const Dataset& data, const std::vector<std::string>& names, StudyResult& out) const {
    const RunRecord& sel = out.runs[out.selection.run];
    const double h = o_.validation_interval > 0 ? o_.validation_interval : sel.interval;
    identify::ClieOptions co = o_.clie;
    co.preprocess = o_.preprocess;
    uncertainty(data, sel, out);
    for (const auto& name : names) {
      try {
        const io::Log log = load_log(data.find(name, o_.trial));
        const preprocess::Samples s = preprocess::preprocess(log, h, o_.preprocess);
        std::string why;
        const auto sim = closed_loop(name, log, why);
        const OpenLoopTorque open = [this](const preprocess::Samples& m, const Eigen::VectorXd& phi) {
          return model_.open_loop_torque(m, phi);
        };
        out.validation.push_back(validate_trajectory(sim.get(), open, s, sel.phi_clie, out.phi_rescue, co, why));
        out.validation.back().trajectory = name;
        // The same vectors against the raw torque, at the log's own rate (the log preprocessed once).
        const preprocess::Samples raw_samples = raw_torque_samples(log);
        const RawTorqueScore raw_clie = raw_torque_error(raw_samples, open, sel.phi_clie),
                             raw = raw_torque_error(raw_samples, open, out.phi_rescue);
        ValidationRecord& v = out.validation.back();
        v.edge_samples = s.report.edge_samples;
        v.raw_rmse_clie = raw_clie.error.rmse;
        v.raw_rmse_rescue = raw.error.rmse;
        v.raw_rmse_joint_rescue = raw.error.rmse_joint;
        v.raw_floor_joint = raw_torque_floor(log, raw_samples);
        v.raw_filter = raw.filter;
        if (out.uncertainty.covariance.size() > 0) {  // the 95 % band, open loop
          v.tau_band = prediction_band(model_, s, out.uncertainty, 0.95);
          const BandCoverage c = band_coverage(s.tau, open(s, out.phi_rescue), v.tau_band);
          v.band_coverage = c.all;
          v.band_coverage_joint = c.joint;
        }
      } catch (const std::exception& e) {
        out.stages.push_back(fmt::format("validation of {}: failed: {}", name, e.what()));
      }
    }
  }

  // The accepted vector's uncertainty on the selected run's samples, the samples it was fitted on.
  void uncertainty(const Dataset& data, const RunRecord& sel, StudyResult& out) const {
    try {
      const io::Log log = load_log(data.find(sel.trajectory, o_.trial));
      const std::vector<preprocess::Samples> s{preprocess::preprocess(log, sel.interval, o_.preprocess)};
      out.uncertainty = prediction_uncertainty(model_, s, out.phi_rescue,
                                               fmt::format("{} at {} ms, the selected run", sel.trajectory,
                                                           static_cast<int>(std::lround(sel.interval * 1000))));
    } catch (const std::exception& e) {
      out.stages.push_back(fmt::format("prediction bands: not made: {}", e.what()));
    }
  }

  const identify::IdentificationModel& model_;
  const identify::ModelDescription& d_;
  const StudyOptions& o_;
  const ClosedLoopSource& loop_;
  std::unique_ptr<identify::InertiaFunction> inertia_;
  identify::AuditDomain domain_;
};

}  // namespace

Study::Study(std::shared_ptr<const identify::IdentificationModel> model, StudyOptions options,
             ClosedLoopSource closed_loop)
    : model_(std::move(model)), o_(std::move(options)), loop_(std::move(closed_loop)) {
  if (!model_) throw std::invalid_argument("Study: no model");
}

StudyResult Study::run() { return StudyRun(*model_, o_, loop_).run(); }

void require_identified(const StudyResult& r) {
  const auto failed = std::count_if(r.runs.begin(), r.runs.end(), [](const RunRecord& run) { return run.failed; });
  if (r.runs.empty() || failed == static_cast<long>(r.runs.size()))
    throw std::runtime_error(
        fmt::format("no run of the study succeeded ({} of {} failed{}): no model was identified", failed, r.runs.size(),
                    r.runs.empty() ? "" : "; the first: " + r.runs.front().id() + ": " + r.runs.front().failure));
  if (r.selection.run < 0)
    throw std::runtime_error(
        fmt::format("no representative run: {}; no model was identified",
                    r.selection.rule.empty() ? "no run produced a final vector" : r.selection.rule));
}

}  // namespace symoro::study
