// The identification study (paper Algorithm 1 and Sec. VI) over a dataset: for every
// identification trajectory and sampling interval, OLS -> all-pose audit -> conditional SDP
// projection -> CLIE -> audit of the CLIE vector; then the PCA clouds, the representative by
// centrality, the post-CLIE rescue (eps = 0) when the representative is not PD, a final
// all-pose audit, and validation on the held-out trajectories.
//
// Runs go to a pool of threads, one trajectory (its log read once, every interval) per task,
// longest first. Each run's record is saved atomically under <out>/runs/ as soon as it ends;
// a rerun skips the runs whose saved fingerprint matches (same data, model and options).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "symoro/error.hpp"
#include "symoro/identify/clie.hpp"
#include "symoro/identify/clie_model.hpp"
#include "symoro/identify/closed_loop_model.hpp"
#include "symoro/identify/dataset.hpp"
#include "symoro/identify/inertia_function_model.hpp"
#include "symoro/identify/least_squares.hpp"
#include "symoro/identify/pca.hpp"
#include "symoro/identify/pd_audit.hpp"
#include "symoro/identify/regression.hpp"
#include "symoro/identify/run_record_io.hpp"
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/identify/study_options.hpp"
#include "symoro/identify/study_result.hpp"
#include "symoro/identify/validation.hpp"
#include "symoro/io/log.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::identify {

namespace detail {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One trajectory at one interval, from its log.
template <class Model>
RunRecord identify_run(const io::Log& log, const ClosedLoopSimulator<Model>& sim, double interval,
                       const StudyOptions& o, const InertiaFunction& inertia, const AuditDomain& domain) {
  RunRecord r;
  r.trajectory = log.meta.trajectory;
  r.interval = interval;
  auto t = std::chrono::steady_clock::now();
  const preprocess::Samples s = preprocess::preprocess(log, interval, o.preprocess);
  r.samples = static_cast<int>(s.time.size());
  const Regression reg = stack_regression<Model>(s);
  LeastSquaresResult ls;
  try {
    ls = least_squares(reg, o.least_squares);
  } catch (const std::invalid_argument& e) {
    throw DataError(log.meta.trajectory, 0, fmt::format("at {} ms: {}", interval * 1e3, e.what()));
  }
  r.kappa = ls.kappa;
  r.kappa_scaled = ls.kappa_scaled;
  r.phi_ols = ls.phi;
  r.std_ols = ls.std_dev;
  r.residual_rms = ls.residual_rms;
  r.weighted = ls.weighted;
  r.t_ols = seconds_since(t);

  t = std::chrono::steady_clock::now();
  const ConditionalProjection cp = conditional_projection(inertia, ls.phi, domain, o.margins, o.projection);
  const double conditional_wall = seconds_since(t);
  r.ols_lambda_min = cp.audit.lambda_min;
  r.ols_worst_pose = cp.audit.worst_pose;
  r.ols_pd = cp.audit.positive_definite();
  r.route = cp.projected ? "O-S-C" : "O-C";
  r.eps = cp.projected ? cp.eps : 0.0;
  r.sdp_feasible = cp.feasible;
  r.phi_sdp = cp.phi;
  r.t_audit = cp.audit.wall;
  r.t_sdp = std::max(0.0, conditional_wall - cp.audit.wall);

  t = std::chrono::steady_clock::now();
  ClieOptions co = o.clie;
  co.preprocess = o.preprocess;
  const ClieResult c = clie<Model>(sim, s, cp.phi, co);
  r.t_clie = seconds_since(t);
  r.clie_success = c.success;
  r.clie_termination = c.start_divergence.diverged ? "start diverged: " + c.start_divergence.describe() : c.termination;
  r.clie_cost_initial = c.initial_cost;
  r.clie_cost_final = c.final_cost;
  r.clie_iterations = c.iterations;
  r.clie_rms = c.rms_final;
  if (c.success) {
    r.phi_clie = c.phi;
    const AuditResult a = audit_pd(inertia, c.phi, domain, o.audit);
    r.clie_lambda_min = a.lambda_min;
    r.clie_pd = a.positive_definite();
    r.t_audit += a.wall;
  }
  return r;
}

}  // namespace detail

template <class Model>
class Study {
 public:
  Study(StudyOptions options, trajectory::TrajectoryDesign design, ClosedLoopSetup setup)
      : o_(std::move(options)), design_(std::move(design)), setup_(std::move(setup)),
        inertia_(make_inertia_function<Model>()), domain_(audit_domain<Model>()) {}

  StudyResult run() {
    const auto t0 = std::chrono::steady_clock::now();
    const Dataset data = read_dataset(o_.data);
    StudyResult out;
    out.robot = Model::robot_name;
    out.model = Model::variant_name;
    for (const auto& p : Model::parameters) {
      out.names.push_back(p.name);
      out.units.push_back(p.unit);
    }
    out.data_source = data.twin.empty() ? "measured (" + data.dir.string() + ")"
                                        : "digital twin (" + data.twin + "), " + data.dir.string();
    const std::vector<std::string> ident = identification_names(data), valid = validation_names(data);

    // Every run's fingerprint; finished runs are loaded, the others form the tasks.
    std::filesystem::create_directories(o_.out / "runs");
    struct Slot {
      std::string trajectory;
      double interval;
      std::filesystem::path file;
      std::string fingerprint;
      std::optional<RunRecord> record;
    };
    std::vector<Slot> slots;
    for (const auto& name : ident) {
      const DatasetRun& run = data.find(name, o_.trial);
      for (double h : o_.intervals) {
        Slot s{name, h, o_.out / "runs" / fmt::format("{}@{}ms.yaml", name, std::lround(h * 1e3)), {}, {}};
        s.fingerprint = fingerprint_of(run_inputs(run, h));
        if (!o_.fresh) s.record = load_run(s.file, s.fingerprint);
        slots.push_back(std::move(s));
      }
    }
    std::vector<std::string> todo;
    for (const auto& name : ident)
      for (const Slot& s : slots)
        if (s.trajectory == name && !s.record) {
          todo.push_back(name);
          break;
        }
    std::stable_sort(todo.begin(), todo.end(), [&](const std::string& a, const std::string& b) {
      return design_.build(a).duration() > design_.build(b).duration();
    });
    const int skipped = static_cast<int>(std::count_if(slots.begin(), slots.end(), [](const Slot& s) { return s.record.has_value(); }));
    if (o_.on_start) o_.on_start(static_cast<int>(slots.size()), skipped);

    const int threads = std::max(1, std::min<int>(o_.threads > 0 ? o_.threads : std::thread::hardware_concurrency(),
                                                  static_cast<int>(todo.size())));
    out.threads = threads;
    std::atomic<size_t> next{0};
    std::mutex m;
    std::string first_error;
    auto work = [&] {
      for (size_t i; (i = next++) < todo.size();) {
        try {
          const std::string& name = todo[i];
          const io::Log log = io::read_log(data.find(name, o_.trial).file);
          const ClosedLoopSimulator<Model> sim(setup_, design_.build(name));
          for (Slot& s : slots) {
            if (s.trajectory != name || s.record) continue;
            RunRecord r = detail::identify_run<Model>(log, sim, s.interval, o_, *inertia_, domain_);
            save_run(r, s.fingerprint, s.file);
            std::lock_guard<std::mutex> lock(m);
            s.record = std::move(r);
            if (o_.on_run) o_.on_run(*s.record);
          }
        } catch (const std::exception& e) {
          std::lock_guard<std::mutex> lock(m);
          if (first_error.empty()) first_error = e.what();
          next = todo.size();
        }
      }
    };
    std::vector<std::thread> pool;
    for (int w = 0; w < threads; ++w) pool.emplace_back(work);
    for (auto& t : pool) t.join();
    if (!first_error.empty()) throw std::runtime_error(first_error);

    for (Slot& s : slots) out.runs.push_back(std::move(*s.record));
    for (const RunRecord& r : out.runs) out.wall_runs += r.t_ols + r.t_audit + r.t_sdp + r.t_clie;

    select_and_accept(out);
    if (out.selection.run >= 0) validate(data, valid, out);
    out.wall = detail::seconds_since(t0);
    return out;
  }

 private:
  std::vector<std::string> identification_names(const Dataset& d) const {
    if (!o_.trajectories.empty()) return o_.trajectories;
    std::vector<std::string> v;
    for (const DatasetRun& r : d.runs)
      if (r.trial == o_.trial && r.family != o_.validation_family) v.push_back(r.trajectory);
    return v;
  }
  std::vector<std::string> validation_names(const Dataset& d) const {
    if (!o_.validation.empty()) return o_.validation;
    std::vector<std::string> v;
    for (const DatasetRun& r : d.runs)
      if (r.trial == o_.trial && r.family == o_.validation_family) v.push_back(r.trajectory);
    return v;
  }

  // What a run's result depends on: the model, the log (its sidecar identifies the data and its
  // size guards against a replaced file), the interval and every option of every stage.
  std::string run_inputs(const DatasetRun& run, double interval) const {
    const auto meta = io::read_log_metadata(run.file);
    return fmt::format("{}/{} | {} {} {} {} {} | {} | {}", Model::robot_name, Model::variant_name, run.file.filename().string(),
                       std::filesystem::file_size(run.file), meta.seed, meta.notes, meta.trial, interval,
                       o_.describe());
  }

  void select_and_accept(StudyResult& out) const {
    if (out.runs.empty()) return;
    if (out.runs.size() == 1) {  // one run (--only X --interval h): it is the candidate, no cloud
      out.selection.run = 0;
      out.selection.centrality = {0.0};
      out.selection.rule = "the only run (no PCA cloud)";
    } else {
      out.pca = pca_clouds(out.runs, o_.pca_components);
      out.selection = select_central(out.runs, out.pca, o_.variance_fraction);
    }
    if (out.selection.run < 0) return;
    const RunRecord& sel = out.runs[out.selection.run];
    out.phi_rescue = sel.phi_clie;
    out.rescued = false;
    if (!sel.clie_pd) {
      ProjectionOptions po = o_.projection;
      po.eps = 0;  // the paper's rescue: a minimal feasibility correction
      const ProjectionResult p = project_pd(*inertia_, sel.phi_clie, domain_, po);
      out.phi_rescue = p.phi;
      out.rescued = true;
      out.rescue_eps = 0;
    }
    // The final audit: denser and with another seed than the ones the pipeline used.
    AuditOptions fa = o_.audit;
    fa.samples *= 4;
    fa.starts *= 2;
    fa.seed += 7919;
    const AuditResult a = audit_pd(*inertia_, out.phi_rescue, domain_, fa);
    out.final_lambda_min = a.lambda_min;
    out.final_worst_pose = a.worst_pose;
    out.accepted = a.positive_definite();
  }

  void validate(const Dataset& data, const std::vector<std::string>& names, StudyResult& out) const {
    const RunRecord& sel = out.runs[out.selection.run];
    const double h = o_.validation_interval > 0 ? o_.validation_interval : sel.interval;
    ClieOptions co = o_.clie;
    co.preprocess = o_.preprocess;
    for (const auto& name : names) {
      const io::Log log = io::read_log(data.find(name, o_.trial).file);
      const preprocess::Samples s = preprocess::preprocess(log, h, o_.preprocess);
      const ClosedLoopSimulator<Model> sim(setup_, design_.build(name));
      out.validation.push_back(validate_trajectory<Model>(sim, s, sel.phi_clie, out.phi_rescue, co));
      out.validation.back().trajectory = name;
    }
  }

  StudyOptions o_;
  trajectory::TrajectoryDesign design_;
  ClosedLoopSetup setup_;
  std::unique_ptr<InertiaFunction> inertia_;
  AuditDomain domain_;
};

}  // namespace symoro::identify
