// symoro.diagnose (docs/python.md): which effects a model misses on a dataset, as dynid diagnose
// finds them (symoro/diagnose/dataset_diagnosis.hpp, the same code), its findings as Python
// objects and its report on disk. Ctrl-C stops it between stages; nothing of it is written then.
#include <atomic>
#include <filesystem>
#include <mutex>
#include <optional>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "interruptible.hpp"
#include "symoro/diagnose/dataset_diagnosis.hpp"
#include "symoro/diagnose/effects.hpp"

namespace symoro::python {

std::shared_ptr<const diagnose::DiagnosisModel> diagnosis_of(py::handle model);
// A loaded model's robot folder when robot_dir is not given (models_binding.cpp).
std::optional<std::filesystem::path> robot_dir_of(py::handle model, const std::optional<std::filesystem::path>& given);

namespace {

py::dict effect_dict(const diagnose::SelectedEffect& e) {
  py::dict x;
  x["effect"] = diagnose::effect_info(e.candidate.kind).name;
  x["joint"] = e.candidate.joint;
  x["label"] = e.candidate.label();
  x["parameters"] = e.candidate.parameters;
  x["units"] = e.candidate.units;
  x["theta"] = e.theta;
  x["std"] = e.std_dev;
  x["magnitude"] = e.magnitude.text;
  x["values"] = e.magnitude.values;
  x["f"] = e.f;
  x["p_value"] = e.p_value;
  x["heldout_gain"] = e.heldout_gain;
  return x;
}

py::dict diagnosis_dict(const diagnose::DatasetDiagnosis& r) {
  const diagnose::Diagnosis& d = r.diagnosis;
  py::dict x;
  x["robot"] = d.robot;
  x["model"] = d.model;
  x["train"] = d.train;
  x["heldout"] = d.heldout;
  py::list effects, dropped, backlash;
  for (const auto& e : d.selection.effects) effects.append(effect_dict(e));
  for (const auto& e : d.selection.dropped) {
    py::dict y;
    y["effect"] = diagnose::effect_info(e.candidate.kind).name;
    y["joint"] = e.candidate.joint;
    y["label"] = e.candidate.label();
    y["magnitude"] = e.magnitude;
    y["reason"] = e.reason;
    dropped.append(y);
  }
  for (const auto& f : d.backlash.findings) {
    py::dict y;
    y["joint"] = f.joint;
    y["width"] = f.width;
    y["measured"] = f.measured;
    y["simulated_before"] = f.simulated_before;
    y["simulated_after"] = f.simulated_after;
    backlash.append(y);
  }
  x["effects"] = effects;
  x["dropped"] = dropped;
  x["stop_reason"] = d.selection.stop_reason;
  // The held-out residual (N m) per joint and over all, before and after the effects: on the
  // diagnosis band, and against the raw torque at the logs' rate (None when it was not scored).
  x["heldout_rmse_before"] = d.selection.before.heldout_rmse;
  x["heldout_rmse_after"] = d.selection.after.heldout_rmse;
  x["heldout_total_before"] = d.selection.before.heldout_total;
  x["heldout_total_after"] = d.selection.after.heldout_total;
  const bool raw = d.raw_note.empty() && d.raw_before.size() > 0;
  x["raw_rmse_before"] = raw ? py::cast(d.raw_before) : py::none();
  x["raw_rmse_after"] = raw ? py::cast(d.raw_after) : py::none();
  x["raw_total_before"] = raw ? py::cast(d.raw_total_before) : py::none();
  x["raw_total_after"] = raw ? py::cast(d.raw_total_after) : py::none();
  x["raw_note"] = d.raw_note;
  x["backlash_judged"] = d.backlash_judged;
  x["backlash"] = backlash;
  x["backlash_note"] = d.backlash_note;
  x["delay"] = d.backlash.delay;
  x["report"] = r.report;
  x["files"] = r.files;
  x["variant"] = r.variant_yaml.empty() ? py::none() : py::cast(r.variant_name);
  x["variant_yaml"] = r.variant_yaml;
  x["variant_file"] = r.variant_file.empty() ? py::none() : py::cast(r.variant_file);
  return x;
}

}  // namespace

void bind_diagnose(py::module_& m) {
  // dynid diagnose's defaults are DatasetDiagnosisOptions' own: taken from it.
  const diagnose::DatasetDiagnosisOptions defaults;
  m.def(
      "diagnose",
      [](py::handle model, const std::filesystem::path& data, const std::filesystem::path& out,
         const std::optional<std::filesystem::path>& robot_dir_given, const std::vector<std::string>& train,
         const std::vector<std::string>& heldout, int trial, double interval_ms, double cutoff,
         const std::vector<std::string>& only, double alpha, double min_gain, double min_torque, bool backlash,
         const std::optional<std::filesystem::path>& params, const std::string& variant, bool apply,
         py::object progress) {
        const auto dm = diagnosis_of(model);
        const std::optional<std::filesystem::path> robot_dir = robot_dir_of(model, robot_dir_given);
        diagnose::DatasetDiagnosisOptions o;
        o.data = data;
        o.out = out;
        o.robot_dir = robot_dir.value_or("");
        o.train = train;
        o.heldout = heldout;
        o.trial = trial;
        o.interval = interval_ms / 1000;
        o.cutoff = cutoff;
        o.only = only;
        o.alpha = alpha;
        o.min_heldout_gain = min_gain;
        o.min_effect_torque = min_torque;
        o.backlash = backlash;
        o.params = params.value_or("");
        o.variant = variant;
        if (apply && !robot_dir)
          throw py::value_error("apply: needs robot_dir, the folder whose robot.yaml gains the variant");
        diagnose::check_request(o);  // before any work
        std::atomic<bool> stop{false};
        o.stop = [&stop] { return stop.load(); };
        std::exception_ptr callback_error;
        std::mutex callback_mutex;
        if (!progress.is_none())
          o.say = [&](const std::string& line) {
            py::gil_scoped_acquire gil;
            try {
              progress(line);
            } catch (py::error_already_set&) {  // the callback raised: stop, and raise it afterwards
              std::lock_guard<std::mutex> lock(callback_mutex);
              if (!callback_error) callback_error = std::current_exception();
              stop = true;
            }
          };
        diagnose::DatasetDiagnosis r;
        try {
          run_interruptible(stop, [&] { r = diagnose::diagnose_dataset(*dm, o); });
        } catch (const diagnose::DiagnosisStopped&) {
          if (callback_error) std::rethrow_exception(callback_error);
          throw;
        }
        if (callback_error) std::rethrow_exception(callback_error);
        py::dict result = diagnosis_dict(r);
        result["applied"] = py::none();
        if (apply) {
          const auto yaml = *robot_dir / "robot.yaml";
          diagnose::add_variant_to_robot_yaml(yaml, r.variant_name, r.variant_yaml);
          result["applied"] = yaml;
        }
        return result;
      },
      py::arg("model"), py::arg("data"), py::arg("out"), py::kw_only(), py::arg("robot_dir") = py::none(),
      py::arg("train") = std::vector<std::string>{}, py::arg("heldout") = std::vector<std::string>{},
      py::arg("trial") = defaults.trial, py::arg("interval_ms") = defaults.interval * 1000,
      py::arg("cutoff") = defaults.cutoff, py::arg("only") = std::vector<std::string>{},
      py::arg("alpha") = defaults.alpha, py::arg("min_gain") = defaults.min_heldout_gain,
      py::arg("min_torque") = defaults.min_effect_torque, py::arg("backlash") = defaults.backlash,
      py::arg("params") = py::none(), py::arg("variant") = "", py::arg("apply") = false,
      py::arg("progress") = py::none());
}

}  // namespace symoro::python
