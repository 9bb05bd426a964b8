// dynid export's body for one model (included by the generated units only): the study's
// accepted base vector -> the physically consistent standard parameters nearest the prior that
// map onto it exactly -> URDF + standard-parameter YAML/CSV.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/QR>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_export.hpp"
#include "dynid_urdf_into.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/model_export.hpp"
#include "symoro/identify/regression.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/identify/urdf_export.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::dynid {

namespace export_detail {

inline void write_text(const std::filesystem::path& file, const std::string& text) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  io::write_file_atomically(file, text);
}

// The study's fitting data: its representative run (parameters.yaml's source_run, e.g.
// "PA11@10ms") of the dataset, preprocessed with the default options, through the full model's
// regression (a variant's fixed parameters included).
struct FittingRun {
  std::string id;
  int trial = 1;
  identify::Regression reg;
};

template <class Full>
FittingRun fitting_run(const std::filesystem::path& params, const std::string& data_dir, int trial) {
  FittingRun f;
  f.id = YAML::LoadFile(params.string())["source_run"].as<std::string>("");
  f.trial = trial;
  const auto at = f.id.find('@');
  if (at == std::string::npos || f.id.size() < at + 4)
    throw UsageError(fmt::format("{}: no source_run like PA11@10ms to measure the torque on", params.string()));
  const io::Dataset data = io::read_dataset(data_dir);
  io::Log log = io::read_run_log(data.find(f.id.substr(0, at), trial), Full::robot_name, Full::nq);
  if (log.samples() > 0) log.time.array() -= log.time(0);
  f.reg = identify::stack_regression<Full>(preprocess::preprocess(log, std::stod(f.id.substr(at + 1)) / 1000, {}));
  return f;
}

// R with |R d| = the RMS over the run's rows of W d: the metric of the predicted torque.
inline Eigen::MatrixXd torque_metric_root(const identify::Regression& reg) {
  const Eigen::MatrixXd W = reg.W / std::sqrt(static_cast<double>(std::max<Eigen::Index>(1, reg.W.rows())));
  return Eigen::HouseholderQR<Eigen::MatrixXd>(W).matrixQR().topRows(W.cols()).triangularView<Eigen::Upper>();
}

inline std::string torque_cost(const FittingRun& f, const Eigen::VectorXd& phi, const Eigen::VectorXd& phi_consistent) {
  auto rms = [](const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / std::max<Eigen::Index>(1, v.size())); };
  const Eigen::VectorXd change = f.reg.W * (phi_consistent - phi);
  return fmt::format("on {} (trial {}, {} samples), the nearest consistent vector (nearest in this run's predicted "
                     "torque) changes the predicted torque by RMS {:.4g} N m (max {:.4g}); the fit's RMS residual "
                     "goes from {:.4g} to {:.4g} N m",
                     f.id, f.trial, f.reg.samples, rms(change), change.cwiseAbs().maxCoeff(), rms(f.reg.y - f.reg.W * phi),
                     rms(f.reg.y - f.reg.W * phi_consistent));
}

}  // namespace export_detail

template <class Full, class Model>
void ExportCommand::run(const Common& common, const ExportOptions& o) {
  if constexpr (identify::detail::HasEffects<Model>::value) {
    throw UsageError(fmt::format("model '{}' has model-gap effect parameters, which have no URDF counterpart and no "
                                 "standard-parameter form: export a study of a model without effects",
                                 Model::variant_name));
  } else {
    using Parent = typename Model::Parent;
    const std::filesystem::path params = std::filesystem::path(o.study) / "report" / "parameters.yaml";
    {
      const YAML::Node root = YAML::LoadFile(params.string());
      const std::string robot = root["robot"] ? root["robot"].as<std::string>() : std::string();
      if (!robot.empty() && robot != common.robot)
        throw UsageError(fmt::format("--robot {}, but {} is a study of '{}'", common.robot, params.string(), robot));
    }
    std::vector<std::string> names;
    for (const auto& p : Model::parameters) names.emplace_back(p.name);
    const Eigen::VectorXd phi = io::read_parameters_yaml(params.string(), names);
    const bool accepted = io::parameters_accepted(params.string());
    if (!accepted && !o.not_accepted)
      throw UsageError(params.string() + ": the study's final audit did not accept these parameters (accepted: false); "
                                         "--not-accepted exports them anyway");

    // The prior.
    std::vector<std::string> standard_names;
    for (const auto& p : Model::standard_parameters) standard_names.emplace_back(p.name);
    Eigen::VectorXd prior;
    std::string prior_what;
    const auto twin_path = common.robot_dir() / "twin.yaml";
    if (o.prior == "zero") {
      prior = Eigen::VectorXd::Zero(Model::ns);
      prior_what = "zero (the consistent set nearest 0)";
    } else if (!o.prior.empty()) {
      prior = io::read_parameters_yaml(o.prior, standard_names);
      prior_what = o.prior;
    } else if (std::filesystem::exists(twin_path)) {
      const twin::TwinConfig tc = twin::read_twin_config(twin_path, Model::nq);
      prior = twin::make_truth<Parent>(tc).standard;
      prior_what = twin_path.string() + " (CAD truth)";
    } else if (std::vector<double> nominal;
               nominal_standard_parameters(common, {Model::standard_parameters.begin(), Model::standard_parameters.end()},
                                           nominal)) {
      // symoroc model's robot.yaml from a URDF: the URDF's own inertials.
      prior = Eigen::Map<const Eigen::VectorXd>(nominal.data(), Model::ns);
      prior_what = (common.robot_dir() / "robot.yaml").string() + " (nominal: the URDF's inertials)";
    } else {
      throw UsageError(fmt::format("robot '{}' has no twin.yaml to take a prior from: give --prior <standard-parameter "
                                   "YAML> or --prior zero (see dynid export --help)",
                                   common.robot));
    }

    identify::ModelExportOptions eo;
    eo.prior = prior;
    eo.prior_what = prior_what;
    eo.study = o.study;
    eo.accepted = accepted;
    eo.margin = o.margin;
    eo.nearest = o.nearest;
    std::optional<export_detail::FittingRun> fitting;
    if (!o.data.empty()) {
      fitting = export_detail::fitting_run<Parent>(params, o.data, o.trial);
      eo.base_metric_root = export_detail::torque_metric_root(fitting->reg);
    }
    eo.cost = [&](const Eigen::VectorXd& target, const Eigen::VectorXd& phi_consistent) {
      return fitting ? export_detail::torque_cost(*fitting, target, phi_consistent)
                     : std::string("--data <the study's dataset> measures the torque it costs on the fitting data (and takes "
                                   "the nearest vector in that metric)");
    };
    const identify::ModelExport e = identify::export_model(*identify::identification_model<Model>(), phi, eo);
    const identify::ConsistencyResult& r = e.consistency;
    const bool nearest = e.nearest;
    const std::string& cost = e.cost;
    const double residual = e.residual;
    std::string urdf_text;
    if (o.into.empty()) {
      urdf_text = identify::urdf_text(e.description);
    } else {
      std::vector<std::string> notes;
      urdf_text = urdf_into(e.description, (common.robot_dir() / "robot.yaml").string(), o.into, notes);
      for (const auto& note : notes) fmt::print("{}\n", note);
    }
    const identify::ModelExportFiles files = identify::write_model_export(e, o.urdf, urdf_text);
    if (nearest)
      fmt::print("WARNING: {}; exported the nearest base vector with a consistent set ({:.4g} away); {}\n", r.message,
                 r.base_distance, cost);
    fmt::print("{}: {}; max |B s - phi| = {:.3g}, lambda_min = {:.4g}, prior {}\n",
               nearest ? "standard parameters of the nearest consistent base vector" : "consistent standard parameters",
               r.message, residual, r.lambda_min, prior_what);
    fmt::print("urdf: {}\nstandard parameters: {}, {}\n", files.urdf.string(), files.yaml.string(), files.csv.string());
  }
}

}  // namespace symoro::dynid
