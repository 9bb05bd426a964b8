// What comes after a study, from Python (docs/python.md): a model's torque on logs (predict, as
// dynid predict) and two studies side by side on their held-out trajectories (compare, as dynid
// compare), returned as NumPy arrays and dicts.
#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "symoro/diagnose/gap_report.hpp"
#include "symoro/model_export/model_export.hpp"
#include "symoro/model_export/mjcf_export.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/study/prediction.hpp"
#include "symoro/study/prediction_band.hpp"
#include "symoro/study/robot_folder.hpp"
#include "symoro/study/validation_io.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/parameters_yaml.hpp"

namespace symoro::python {

std::shared_ptr<const identify::IdentificationModel> identification_of(py::handle model);
// A loaded model's robot folder when robot_dir is not given (models_binding.cpp).
std::optional<std::filesystem::path> robot_dir_of(py::handle model, const std::optional<std::filesystem::path>& given);

namespace {
// The parameters file `params` names (a str or a path other than "nominal"), if it names one.
std::optional<std::filesystem::path> parameters_file(py::handle params) {
  if (!py::isinstance<py::str>(params) && !py::hasattr(params, "__fspath__")) return std::nullopt;
  const auto file = params.cast<std::filesystem::path>();
  if (file == "nominal") return std::nullopt;
  return file;
}
}  // namespace

// phi from an array, a parameters file (a study's report/parameters.yaml), or "nominal" (the
// robot folder's robot.yaml). Shared with payload_binding.cpp.
Eigen::VectorXd parameters_of(const identify::IdentificationModel& model, py::handle params,
                              const std::optional<std::filesystem::path>& robot_dir) {
  const identify::ModelDescription& d = model.description();
  if (py::isinstance<py::str>(params) && params.cast<std::string>() == "nominal") {
    std::vector<double> s;
    if (!robot_dir || !study::nominal_standard_parameters(*robot_dir, d.standard, s))
      throw py::value_error("params='nominal': " +
                            (robot_dir ? (*robot_dir / "robot.yaml").string() +
                                             " has no nominal parameters (symoroc model writes them from a URDF)"
                                       : std::string("no robot_dir given")));
    return model.base_from_standard(Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size())));
  }
  if (const auto file = parameters_file(params)) {
    std::vector<std::string> names;
    for (const auto& p : d.parameters) names.push_back(p.name);
    return io::read_parameters_yaml(file->string(), names);
  }
  const StateArg phi = state_arg(params, "params", d.np);
  if (phi.batch) throw py::value_error(fmt::format("params: one vector of {} parameters expected", d.np));
  return Eigen::Map<const Eigen::VectorXd>(phi.data(), d.np);
}

namespace {

py::dict prediction_dict(const std::string& name, const study::Prediction& p) {
  py::dict x;
  x["name"] = name;
  x["time"] = p.samples.time;
  x["q"] = p.samples.q;
  x["qd"] = p.samples.qd;
  x["qdd"] = p.samples.qdd;
  x["tau"] = p.samples.tau;
  x["tau_model"] = p.tau_model;
  x["rmse"] = p.rmse;
  x["rms"] = p.rms;
  x["raw_rmse"] = p.raw.error.rmse_joint;
  x["raw_rmse_overall"] = p.raw.error.rmse;
  x["raw_samples"] = p.raw.samples;
  x["raw_floor"] = p.raw.floor_joint;  // the raw torque's own content above the cutoff, per joint
  // What the preprocessing left out or filtered through (preprocess/edges.hpp), and its line.
  x["edge_samples"] = p.samples.report.edge_samples;
  x["context_rows"] = p.samples.report.context_rows;
  x["preprocessing"] = p.samples.report.summary();
  return x;
}

}  // namespace

double torque_delay_of(py::handle params, std::optional<double> given_ms) {
  if (given_ms) return *given_ms;
  // A parameters file's timing (the arm's identification's, as dynid predict and payload take it).
  const auto file = parameters_file(params);
  return file ? io::parameters_torque_delay(file->string()).value_or(0) * 1000 : 0.0;
}

void bind_results(py::module_& m) {
  m.def(
      "predict",
      [](py::handle model, py::handle params, const std::filesystem::path& input, double interval_ms,
         std::optional<double> torque_delay_given, int trial,
         const std::optional<std::filesystem::path>& robot_dir_given, double band,
         const std::optional<std::filesystem::path>& uncertainty_file) {
        // dynid predict's ranges (a NaN or infinite value is named, never computed with).
        const double torque_delay_ms = torque_delay_of(params, torque_delay_given);
        if (!(std::isfinite(interval_ms) && interval_ms >= 1 && interval_ms <= 10000))
          throw py::value_error(fmt::format("interval_ms {}: must be from 1 to 10000", interval_ms));
        if (!(std::isfinite(torque_delay_ms) && torque_delay_ms >= -1000 && torque_delay_ms <= 1000))
          throw py::value_error(fmt::format("torque_delay_ms {}: must be from -1000 to 1000", torque_delay_ms));
        if (trial < 1) throw py::value_error(fmt::format("trial {}: must be 1 or more", trial));
        if (!(std::isfinite(band) && band >= 0 && band < 1))
          throw py::value_error(fmt::format("band {}: must be from 0 (none) to below 1", band));
        const auto id = identification_of(model);
        const std::optional<std::filesystem::path> robot_dir = robot_dir_of(model, robot_dir_given);
        const identify::ModelDescription& d = id->description();
        const Eigen::VectorXd phi = parameters_of(*id, params, robot_dir);
        // One log, or every run of a dataset's trial (as dynid predict).
        const std::vector<io::NamedLog> logs = io::read_input_logs(input, d.robot, d.nq, trial);
        if (logs.empty()) throw py::value_error(fmt::format("{}: no run of trial {}", input.string(), trial));
        // The band's uncertainty: given, or report/uncertainty.yaml beside a parameters file.
        std::optional<study::PredictionUncertainty> u;
        std::optional<std::filesystem::path> ufile = uncertainty_file;
        if (const auto file = parameters_file(params); !ufile && band > 0 && file) {
          const auto beside = file->parent_path() / "uncertainty.yaml";
          if (std::filesystem::exists(beside)) ufile = beside;
        }
        if (ufile && band > 0) {
          std::vector<std::string> names;
          for (const auto& p : d.parameters) names.push_back(p.name);
          u = study::read_uncertainty_yaml(ufile->string(), names);
        }
        std::vector<study::Prediction> out(logs.size());
        {
          py::gil_scoped_release release;
          for (std::size_t i = 0; i < logs.size(); ++i)
            out[i] = study::predict(logs[i].log, *id, phi, {interval_ms / 1000, torque_delay_ms / 1000});
        }
        py::list result;
        for (std::size_t i = 0; i < logs.size(); ++i) {
          py::dict x = prediction_dict(logs[i].name, out[i]);
          if (u) {
            const Eigen::MatrixXd b = study::prediction_band(*id, out[i].samples, *u, band);
            const study::BandCoverage c = study::band_coverage(out[i].samples.tau, out[i].tau_model, b);
            x["tau_band"] = b;
            x["band_coverage"] = c.all;
            x["band_coverage_joint"] = c.joint;
          }
          result.append(x);
        }
        return result;
      },
      py::arg("model"), py::arg("params"), py::arg("input"), py::kw_only(),
      py::arg("interval_ms") = study::PredictionOptions{}.interval * 1000, py::arg("torque_delay_ms") = py::none(),
      py::arg("trial") = 1, py::arg("robot_dir") = py::none(), py::arg("band") = 0.95,
      py::arg("uncertainty") = py::none(),
      "The model's torque on a log or a dataset's runs: a list of {'name', 'time', 'q', 'qd', 'qdd', 'tau', "
      "'tau_model', "
      "'rmse', 'rms', 'raw_rmse', 'raw_rmse_overall', 'raw_samples', 'edge_samples', 'context_rows', 'preprocessing'}; "
      "params: an array, a parameters file or 'nominal' (with robot_dir). With a study's report/uncertainty.yaml "
      "beside "
      "the parameters file (or given as uncertainty=), also 'tau_band' (the band's half-width at level `band`), "
      "'band_coverage' and 'band_coverage_joint' (the share of samples inside)");

  m.def(
      "compare",
      [](const std::filesystem::path& before_dir, const std::filesystem::path& after_dir,
         const std::filesystem::path& out, const std::string& trajectory, const std::vector<int>& joints) {
        const study::StudyValidation before = study::read_validation(before_dir);
        const study::StudyValidation after = study::read_validation(after_dir);
        const diagnose::GapComparison c = diagnose::compare_studies(before, after);
        diagnose::GapReportOptions ro;
        try {
          ro = diagnose::gap_report_options(before_dir, after_dir, c, trajectory, joints);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(fmt::format("joints: {}", e.what()));
        }
        diagnose::write_gap_report(before, after, c, out, ro);
        py::list trajectories;
        for (const auto& t : c.trajectories) {
          py::dict x;
          x["trajectory"] = t.trajectory;
          x["kind"] = t.kind;
          x["interval"] = t.interval;
          x["samples"] = t.samples;
          x["rmse_before"] = t.rmse_before;
          x["rmse_after"] = t.rmse_after;
          x["joint_before"] = t.joint_before;
          x["joint_after"] = t.joint_after;
          trajectories.append(x);
        }
        py::dict r;
        r["robot"] = c.robot;
        r["before_model"] = c.before_model;
        r["after_model"] = c.after_model;
        r["trajectories"] = trajectories;
        r["rmse_before"] = c.rmse_before;
        r["rmse_after"] = c.rmse_after;
        r["joint_before"] = c.joint_before;
        r["joint_after"] = c.joint_after;
        r["added"] = c.added;
        r["report"] = out / "gap.md";
        return r;
      },
      py::arg("before"), py::arg("after"), py::arg("out"), py::kw_only(), py::arg("trajectory") = "",
      py::arg("joints") = std::vector<int>{},
      "Two studies of one robot on the same data side by side on their held-out trajectories (dynid compare): gap.md "
      "and "
      "figures in out, the numbers as a dict");
}

void bind_export(py::module_& m) {
  m.def(
      "export_urdf",
      [](py::handle model, const std::filesystem::path& study, const std::filesystem::path& urdf, py::handle prior,
         const std::optional<std::filesystem::path>& robot_dir_given, double margin, bool nearest, bool not_accepted,
         const std::optional<std::filesystem::path>& mjcf) {
        const auto id = identification_of(model);
        const std::optional<std::filesystem::path> robot_dir = robot_dir_of(model, robot_dir_given);
        const identify::ModelDescription& d = id->description();
        if (const std::vector<std::string> effects = identify::effect_parameter_names(d); !effects.empty())
          throw py::value_error(
              fmt::format("model '{}' has model-gap effect parameters ({}), which no URDF or MJCF field carries: "
                          "export a study of a model without effects",
                          d.variant, fmt::join(effects, ", ")));
        if (!id->supports_physical_consistency())
          throw py::value_error(fmt::format("model '{}' has no physical consistency to export", d.variant));
        // As dynid export: the study's accepted vector, refused when its final audit did not accept it.
        const std::filesystem::path params = study / "report" / "parameters.yaml";
        std::vector<std::string> names;
        for (const auto& p : d.parameters) names.push_back(p.name);
        const Eigen::VectorXd phi = io::read_parameters_yaml(params.string(), names);
        const bool accepted = io::parameters_accepted(params.string());
        if (!accepted && !not_accepted)
          throw py::value_error(params.string() +
                                ": the study's final audit did not accept these parameters (accepted: false); "
                                "not_accepted=True exports them anyway");
        model_export::ModelExportOptions eo;
        std::vector<std::string> standard;
        for (const auto& p : d.standard) standard.push_back(p.name);
        const std::string prior_name = py::isinstance<py::str>(prior) ? prior.cast<std::string>() : "";
        if (prior_name == "zero") {
          eo.prior = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d.standard.size()));
          eo.prior_what = "zero (the consistent set nearest 0)";
        } else if (prior.is_none() || prior_name == "nominal") {
          std::vector<double> s;
          if (!robot_dir || !study::nominal_standard_parameters(*robot_dir, d.standard, s))
            throw py::value_error(
                "prior: robot.yaml's nominal parameters are needed (robot_dir=, a folder symoroc model wrote "
                "from a URDF), else give prior='zero', a standard-parameter file or an array");
          eo.prior = Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size()));
          eo.prior_what = (*robot_dir / "robot.yaml").string() + " (nominal: the URDF's inertials)";
        } else if (!prior_name.empty() || py::hasattr(prior, "__fspath__")) {
          const auto file = prior.cast<std::filesystem::path>();
          eo.prior = io::read_parameters_yaml(file.string(), standard);
          eo.prior_what = file.string();
        } else {
          const StateArg s = state_arg(prior, "prior", static_cast<int>(d.standard.size()));
          if (s.batch) throw py::value_error("prior: one vector of standard parameters expected");
          eo.prior = Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(d.standard.size()));
          eo.prior_what = "an array given from Python";
        }
        eo.study = study.string();
        eo.accepted = accepted;
        eo.margin = margin;
        eo.nearest = nearest;
        model_export::ModelExport e;
        model_export::ModelExportFiles files;
        {
          py::gil_scoped_release release;
          e = model_export::export_model(*id, phi, eo);
          files = model_export::write_model_export(e, urdf, model_export::urdf_text(e.description));
          if (mjcf) io::write_file_atomically(*mjcf, model_export::mjcf_text(e.description, d.gravity));
        }
        py::dict r;
        r["urdf"] = files.urdf;
        if (mjcf) r["mjcf"] = *mjcf;
        r["standard_yaml"] = files.yaml;
        r["standard_csv"] = files.csv;
        r["s"] = e.description.s;
        r["standard_names"] = standard;
        r["residual"] = e.residual;
        r["lambda_min"] = e.consistency.lambda_min;
        r["nearest"] = e.nearest;
        r["message"] = e.consistency.message;
        return r;
      },
      py::arg("model"), py::arg("study"), py::arg("urdf"), py::kw_only(), py::arg("prior") = py::none(),
      py::arg("robot_dir") = py::none(), py::arg("margin") = model_export::ModelExportOptions{}.margin,
      py::arg("nearest") = model_export::ModelExportOptions{}.nearest, py::arg("not_accepted") = false,
      py::arg("mjcf") = py::none(),
      "The study's accepted parameters as a URDF (dynid export): the physically consistent standard parameters nearest "
      "the prior that reproduce them, written to urdf and <stem>.standard.yaml/.csv; with mjcf=path, as a MuJoCo "
      "model too (docs/mjcf.md)");
}

}  // namespace symoro::python
