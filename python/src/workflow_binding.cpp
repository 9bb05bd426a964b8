// The workflow from Python (docs/python.md): import a controller's export into a dataset, and
// run the identification study with dynid identify's options, its results as Python objects.
// A study runs in a thread of its own while the calling thread waits with the GIL released and
// checks for Ctrl-C: KeyboardInterrupt stops it cleanly (StudyOptions::stop: the runs in
// progress finish and are saved, a rerun resumes).
#include <algorithm>
#include <atomic>
#include <mutex>
#include <optional>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "interruptible.hpp"
#include "symoro/study/report.hpp"
#include "symoro/study/robot_folder.hpp"
#include "symoro/study/study.hpp"
#include "symoro/study/request.hpp"
#include "symoro/study/validation_io.hpp"
#include "symoro/io/folder_lock.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/import_bag.hpp"
#include "symoro/parallel/farm.hpp"

namespace symoro::python {

std::shared_ptr<const identify::IdentificationModel> identification_of(py::handle model);
// A loaded model's robot folder when robot_dir is not given (models_binding.cpp).
std::optional<std::filesystem::path> robot_dir_of(py::handle model, const std::optional<std::filesystem::path>& given);

namespace {

py::dict run_record(const study::RunRecord& r) {
  py::dict d;
  d["id"] = r.id();
  d["trajectory"] = r.trajectory;
  d["interval"] = r.interval;
  d["failed"] = r.failed;
  d["failure"] = r.failure;
  d["samples"] = r.samples;
  d["kappa"] = r.kappa;
  d["route"] = r.route;
  d["residual_rms"] = r.residual_rms;
  d["phi_ols"] = r.phi_ols;
  d["std_ols"] = r.std_ols;
  d["ols_lambda_min"] = r.ols_lambda_min;
  d["eps"] = r.eps;
  d["phi_sdp"] = r.phi_sdp;
  d["clie_ran"] = r.clie_ran;
  d["phi_clie"] = r.phi_clie;
  d["clie_termination"] = r.clie_termination;
  d["clie_iterations"] = r.clie_iterations;
  d["clie_lambda_min"] = r.clie_lambda_min;
  d["clie_pd"] = r.clie_pd;
  return d;
}

py::dict validation_record(const study::ValidationRecord& v) {
  py::dict d;
  d["trajectory"] = v.trajectory;
  d["kind"] = v.kind;
  d["note"] = v.note;
  d["interval"] = v.interval;
  d["rmse_clie"] = v.rmse_clie;
  d["rmse_rescue"] = v.rmse_rescue;
  d["mne_clie"] = v.mne_clie;
  d["mne_rescue"] = v.mne_rescue;
  d["rmse_joint_rescue"] = v.rmse_joint_rescue;
  d["nrmse_joint_rescue"] = v.nrmse_joint_rescue;
  d["raw_rmse_rescue"] = v.raw_rmse_rescue;
  d["raw_rmse_joint_rescue"] = v.raw_rmse_joint_rescue;
  d["time"] = v.time;
  d["tau_measured"] = v.tau_measured;
  d["tau_rescue"] = v.tau_rescue;
  return d;
}

}  // namespace

void bind_workflow(py::module_& m) {
  m.def(
      "import_logs",
      [](py::handle model, const std::filesystem::path& out, const std::vector<std::filesystem::path>& files,
         const std::string& time, const std::string& q, const std::string& tau, const std::string& qd,
         const std::string& q_ref, const std::string& qd_ref, const std::string& qdd_ref, const std::string& time_unit,
         const std::string& angle, double torque_scale, const std::string& header, const std::string& delimiter,
         const std::optional<std::filesystem::path>& mapping, const std::vector<std::string>& names,
         const std::vector<std::filesystem::path>& heldout, double split, bool allow_implausible,
         const std::string& topic, const std::string& stamp, const std::string& effort,
         const std::vector<double>& torque_constants) {
        const identify::ModelDescription& d = identification_of(model)->description();
        io::DatasetImport di;
        di.target = io::import_target(d.robot, d.joints);
        // As dynid import: the arguments over the mapping file's settings (or the defaults).
        io::ImportMapping& mp = di.mapping;
        if (mapping) mp = io::read_import_mapping(*mapping);
        io::apply_settings(
            mp, {time, q, qd, tau, q_ref, qd_ref, qdd_ref, time_unit, angle, header, delimiter, torque_scale});
        const bool text =
            std::any_of(files.begin(), files.end(), [](const std::filesystem::path& f) { return !io::is_bag(f); });
        if (text && (mp.time.empty() || mp.q.empty() || mp.tau.empty()))
          throw py::value_error("say which columns hold time, q and tau: time=, q=, tau=, or mapping='map.yaml'");
        // ROS 2 bags (an .mcap file or a bag folder) as dynid import reads them, with robot.yaml's torque
        // constants when none are given (the loaded model's folder).
        const std::optional<std::filesystem::path> dir = robot_dir_of(model, std::nullopt);
        try {
          di.bag = io::bag_settings(topic, stamp, effort, torque_constants, d.joints.size(),
                                    dir ? *dir / "robot.yaml" : std::filesystem::path());
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("stamp, effort, torque_constants: ") + e.what());
        }
        if (!names.empty() && names.size() != files.size())
          throw py::value_error(fmt::format("names: {} names for {} input files", names.size(), files.size()));
        for (const auto& h : heldout)
          if (std::find(files.begin(), files.end(), h) == files.end())
            throw py::value_error(fmt::format("heldout: {} is not one of the input files", h.string()));
        di.split = split;
        di.allow_implausible = allow_implausible;
        for (std::size_t i = 0; i < files.size(); ++i)
          di.inputs.push_back({files[i], names.empty() ? "" : names[i],
                               std::find(heldout.begin(), heldout.end(), files[i]) != heldout.end()});
        io::DatasetImportResult r;
        {
          py::gil_scoped_release release;
          r = io::import_dataset(out, di);
        }
        py::list logs;
        for (const io::ImportedLog& l : r.logs) {
          py::dict x;
          x["input"] = l.input;
          x["name"] = l.log.meta.trajectory;
          x["rows"] = l.rows;
          x["samples"] = l.log.samples();
          x["stale_rows"] = l.stale_lines.size();
          x["duplicate_rows"] = l.duplicate_lines.size();
          x["sample_time"] = l.log.meta.sample_time;
          x["velocity"] = l.log.meta.velocity == io::Velocity::measured ? "measured" : "differentiated";
          x["remarks"] = l.remarks;
          logs.append(x);
        }
        py::list runs;
        for (const auto& run : r.runs) {
          py::dict x;
          x["trajectory"] = run.trajectory;
          x["family"] = run.family;
          x["file"] = run.file;
          x["window"] = py::make_tuple(run.window_start, run.window_end);
          runs.append(x);
        }
        py::dict result;
        result["dataset"] = r.dataset;
        result["logs"] = logs;
        result["runs"] = runs;
        return result;
      },
      py::arg("model"), py::arg("out"), py::arg("files"), py::kw_only(), py::arg("time") = "", py::arg("q") = "",
      py::arg("tau") = "", py::arg("qd") = "", py::arg("q_ref") = "", py::arg("qd_ref") = "", py::arg("qdd_ref") = "",
      py::arg("time_unit") = "", py::arg("angle") = "", py::arg("torque_scale") = 0.0, py::arg("header") = "",
      py::arg("delimiter") = "", py::arg("mapping") = py::none(), py::arg("names") = std::vector<std::string>{},
      py::arg("heldout") = std::vector<std::filesystem::path>{}, py::arg("split") = 0.0,
      py::arg("allow_implausible") = false, py::arg("topic") = "/joint_states", py::arg("stamp") = "header",
      py::arg("effort") = "torque", py::arg("torque_constants") = std::vector<double>{},
      "Controllers' exports (CSV, text) or ROS 2 bags (.mcap files, bag folders) into a dataset folder (dynid import)");

  // dynid identify's defaults are the request's (StudyOptions' own): taken from it.
  const study::StudyRequest defaults;
  m.def(
      "identify",
      [](py::handle model, const std::filesystem::path& data, const std::filesystem::path& out,
         const std::optional<std::filesystem::path>& robot_dir_arg,
         const std::optional<std::filesystem::path>& design_arg, const std::vector<std::string>& only,
         const std::vector<std::string>& validation, const std::vector<double>& intervals_ms, std::optional<int> jobs,
         int trial, bool weighted, bool fresh, bool in_process, double torque_delay_ms, bool logged_velocity,
         int clie_iterations, double clie_std_bound, double clie_noise_floor, const std::string& projection_metric,
         const std::string& consistency, bool physical_start, const std::string& rescue_metric, py::object rescue_prior,
         double rescue_prior_weight, const std::vector<double>& rescue_prior_weights, double validation_ms, bool report,
         py::object progress) {
        const std::shared_ptr<const identify::IdentificationModel> id = identification_of(model);
        const identify::ModelDescription& d = id->description();
        const std::filesystem::path robot_dir = robot_dir_of(model, robot_dir_arg).value_or(""),
                                    design = design_arg.value_or("");
        // As dynid identify: the same request, the same translation (study/request.hpp).
        study::StudyRequest q;
        q.data = data.string();
        q.out = out.string();
        q.trial = trial;
        q.threads = jobs.value_or(0);  // None: every core (StudyOptions' 0); a value given is checked
        if (jobs && (*jobs < 1 || *jobs > 1024))
          throw py::value_error(fmt::format("--jobs {}: must be from 1 to 1024 (None: every core)", *jobs));
        q.fresh = fresh;
        q.in_process = in_process;
        q.only = only;
        q.validation = validation;
        q.intervals_ms = intervals_ms;
        q.weighted = weighted;
        q.torque_delay_ms = torque_delay_ms;
        q.logged_velocity = logged_velocity;
        q.clie_iterations = clie_iterations;
        q.clie_std_bound = clie_std_bound;
        q.clie_noise_floor = clie_noise_floor;
        q.projection_metric = projection_metric;
        q.consistency = consistency;
        q.physical_start = physical_start;
        q.rescue_metric = rescue_metric;
        q.rescue_prior_weight = rescue_prior_weight;
        q.rescue_prior_weights = rescue_prior_weights;
        q.validation_ms = validation_ms;
        // The rescue's prior: a name or a file as dynid's, or an array of standard parameters.
        const bool array_prior = !rescue_prior.is_none() && !py::isinstance<py::str>(rescue_prior) &&
                                 !py::hasattr(rescue_prior, "__fspath__");
        if (!rescue_prior.is_none() && !array_prior) q.rescue_prior = py::str(rescue_prior).cast<std::string>();
        if (array_prior) q.rescue_prior = "zero";  // replaced below
        study::StudyOptions so = study::study_options(q, d, robot_dir);
        if (array_prior) {
          const StateArg s = state_arg(rescue_prior, "rescue_prior", static_cast<int>(d.standard.size()));
          so.rescue_prior = Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(d.standard.size()));
          so.rescue_prior_source = "an array given from Python";
        }
        study::ClosedLoopSource loop;
        if (!robot_dir.empty())
          loop = study::closed_loop_source(robot_dir, d, design);
        else
          loop.why = "no robot folder given (robot_dir): no controller description";

        std::atomic<bool> stop{false};
        so.stop = [&stop] { return stop.load(); };
        std::exception_ptr callback_error;
        std::mutex callback_mutex;
        if (!progress.is_none()) {
          auto total = std::make_shared<int>(0), count = std::make_shared<int>(0);
          so.on_start = [total, count](int t, int skipped) {
            *total = t;
            *count = skipped;
          };
          so.on_run = [&, total, count](const study::RunRecord& r) {
            py::gil_scoped_acquire gil;
            try {
              progress(++*count, *total, run_record(r));
            } catch (py::error_already_set&) {  // the callback raised: stop, and raise it afterwards
              std::lock_guard<std::mutex> lock(callback_mutex);
              if (!callback_error) callback_error = std::current_exception();
              stop = true;
            }
          };
        }
        study::StudyResult r;
        std::optional<io::FolderLock> lock;
        // Under mpirun (docs/scaling.md) every rank calls this; rank 0 holds the folder, gathers the
        // records and reports, the others run their share of the runs and return None.
        const bool coordinator = parallel::place().coordinator();
        if (coordinator) lock.emplace(out, "symoro.identify");  // one study per folder at a time
        try {
          run_interruptible(stop, [&] {
            r = study::Study(id, so, std::move(loop)).run();
            if (!coordinator) return;
            study::write_validation(r, out);
            if (report) study::write_report(r, out / "report");
          });
        } catch (const study::StudyStopped&) {
          if (callback_error) std::rethrow_exception(callback_error);  // the callback's own exception stopped it
          throw;
        }
        if (callback_error) std::rethrow_exception(callback_error);
        if (!coordinator) return py::object(py::none());
        // As dynid identify: a study without a model fails, after its records and report are written.
        study::require_identified(r);

        py::dict result;
        result["robot"] = r.robot;
        result["model"] = r.model.empty() ? std::string("full") : r.model;
        result["names"] = r.names;
        result["units"] = r.units;
        py::list runs;
        for (const auto& run : r.runs) runs.append(run_record(run));
        result["runs"] = runs;
        py::dict selection;
        selection["run"] = r.selection.run;
        selection["id"] = r.selection.run >= 0 ? r.runs[r.selection.run].id() : std::string();
        selection["rule"] = r.selection.rule;
        selection["centrality"] = r.selection.centrality;
        result["selection"] = selection;
        result["phi"] = r.phi_rescue;
        py::dict parameters;
        for (std::size_t i = 0; i < r.names.size() && static_cast<Eigen::Index>(i) < r.phi_rescue.size(); ++i)
          parameters[py::str(r.names[i])] = r.phi_rescue[static_cast<Eigen::Index>(i)];
        result["parameters"] = parameters;
        result["accepted"] = r.accepted;
        result["not_accepted_because"] = study::acceptance_verdict(r).reasons;  // empty when accepted
        result["final_audit"] = r.final_audit;
        result["rescued"] = r.rescued;
        result["consistency"] = r.consistency;
        result["final_lambda_min"] = r.final_lambda_min;
        result["final_consistent"] = r.final_consistent;
        py::list valid;
        for (const auto& v : r.validation) valid.append(validation_record(v));
        result["validation"] = valid;
        result["truth"] = r.truth;
        result["stages"] = r.stages;
        result["data_source"] = r.data_source;
        result["out"] = out;
        result["validation_file"] = out / "validation.yaml";
        result["report"] = report ? py::object(py::cast(out / "report" / "report.md")) : py::none();
        return py::object(std::move(result));
      },
      py::arg("model"), py::arg("data"), py::arg("out"), py::kw_only(), py::arg("robot_dir") = py::none(),
      py::arg("design") = py::none(), py::arg("only") = std::vector<std::string>{},
      py::arg("validation") = std::vector<std::string>{}, py::arg("intervals_ms") = std::vector<double>{},
      py::arg("jobs") = py::none(), py::arg("trial") = defaults.trial, py::arg("weighted") = defaults.weighted,
      py::arg("fresh") = defaults.fresh, py::arg("in_process") = defaults.in_process,
      py::arg("torque_delay_ms") = defaults.torque_delay_ms, py::arg("logged_velocity") = defaults.logged_velocity,
      py::arg("clie_iterations") = defaults.clie_iterations, py::arg("clie_std_bound") = defaults.clie_std_bound,
      py::arg("clie_noise_floor") = defaults.clie_noise_floor,
      py::arg("projection_metric") = defaults.projection_metric, py::arg("consistency") = defaults.consistency,
      py::arg("physical_start") = defaults.physical_start, py::arg("rescue_metric") = defaults.rescue_metric,
      py::arg("rescue_prior") = py::none(), py::arg("rescue_prior_weight") = defaults.rescue_prior_weight,
      py::arg("rescue_prior_weights") = defaults.rescue_prior_weights,
      py::arg("validation_ms") = defaults.validation_ms, py::arg("report") = true, py::arg("progress") = py::none());
}

}  // namespace symoro::python
