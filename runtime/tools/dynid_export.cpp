// dynid export --urdf: a study's accepted base parameters as a URDF of the robot with
// physically consistent inertials (identify/physical_consistency.hpp, model_export/urdf_export.hpp),
// and the standard parameters beside it (<name>.standard.yaml, <name>.standard.csv).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/QR>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_export.hpp"
#include "dynid_robots.hpp"
#include "dynid_numbers.hpp"
#include "dynid_urdf_into.hpp"
#include "symoro/payload/payload_formats.hpp"
#include "symoro/model_export/model_export.hpp"
#include "symoro/identify/regression.hpp"
#include "symoro/model_export/urdf_export.hpp"
#include "symoro/model_export/mjcf_export.hpp"
#include "symoro/io/folder_lock.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::dynid {

namespace {

// The model label the study was identified with (report/parameters.yaml `model:`; "" is the
// full model), to pick the instantiation when --model is not given.
std::string study_model(const std::string& file) {
  if (!std::filesystem::exists(file))
    throw UsageError(file + ": not found (is --study a dynid identify folder with its report?)");
  try {
    const YAML::Node root = io::load_yaml_file(file);
    // A study that produced no model says so here, before its (empty) parameter list is read
    // against the model's names.
    const YAML::Node list = root["parameters"];
    if (!list || !list.IsSequence() || list.size() == 0)
      throw UsageError(
          fmt::format("{}: the study has no model to export: no run produced a final vector, so there is "
                      "no representative and no accepted parameters (see the study's report.md)",
                      file));
    const std::string m = root["model"] ? root["model"].as<std::string>() : std::string();
    return m.empty() ? "full" : m;
  } catch (const YAML::BadFile&) {
    throw UsageError(file + ": not found (is --study a dynid identify folder with its report?)");
  } catch (const YAML::Exception& e) {
    throw UsageError(file + ": invalid YAML: " + e.what());
  }
}

}  // namespace

namespace export_detail {

void write_text(const std::filesystem::path& file, const std::string& text) {
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

FittingRun fitting_run(const identify::IdentificationModel& full, const std::filesystem::path& params,
                       const std::string& data_dir, int trial) {
  FittingRun f;
  f.id = io::load_yaml_file(params)["source_run"].as<std::string>("");
  f.trial = trial;
  const auto at = f.id.find('@');
  if (at == std::string::npos || f.id.size() < at + 4)
    throw UsageError(fmt::format("{}: no source_run like PA11@10ms to measure the torque on", params.string()));
  const io::Dataset data = io::read_dataset(data_dir);
  io::Log log = io::read_run_log(data.find(f.id.substr(0, at), trial), full.description().robot, full.description().nq);
  if (log.samples() > 0) log.time.array() -= log.time(0);
  f.reg = full.stack_regression(preprocess::preprocess(log, std::stod(f.id.substr(at + 1)) / 1000, {}));
  return f;
}

// R with |R d| = the RMS over the run's rows of W d: the metric of the predicted torque.
Eigen::MatrixXd torque_metric_root(const identify::Regression& reg) {
  const Eigen::MatrixXd W = reg.W / std::sqrt(static_cast<double>(std::max<Eigen::Index>(1, reg.W.rows())));
  return Eigen::HouseholderQR<Eigen::MatrixXd>(W).matrixQR().topRows(W.cols()).triangularView<Eigen::Upper>();
}

std::string torque_cost(const FittingRun& f, const Eigen::VectorXd& phi, const Eigen::VectorXd& phi_consistent) {
  auto rms = [](const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / std::max<Eigen::Index>(1, v.size())); };
  const Eigen::VectorXd change = f.reg.W * (phi_consistent - phi);
  return fmt::format(
      "on {} (trial {}, {} samples), the nearest consistent vector (nearest in this run's predicted "
      "torque) changes the predicted torque by RMS {:.4g} N m (max {:.4g}); the fit's RMS residual "
      "goes from {:.4g} to {:.4g} N m",
      f.id, f.trial, f.reg.samples, rms(change), change.cwiseAbs().maxCoeff(), rms(f.reg.y - f.reg.W * phi),
      rms(f.reg.y - f.reg.W * phi_consistent));
}

// The study's parameters (its report/parameters.yaml), checked as control checks them: of this
// robot, as identify wrote them (its digest), accepted; --not-accepted exports them anyway.
Eigen::VectorXd read_study_parameters(const Common& common, const ExportOptions& options,
                                      const identify::ModelDescription& d, const std::filesystem::path& params,
                                      bool& accepted) {
  {
    const YAML::Node root = io::load_yaml_file(params);
    const std::string robot = root["robot"] ? root["robot"].as<std::string>() : std::string();
    if (!robot.empty() && robot != common.robot)
      throw UsageError(fmt::format("--robot {}, but {} is a study of '{}'", common.robot, params.string(), robot));
  }
  std::vector<std::string> names;
  for (const auto& p : d.parameters) names.emplace_back(p.name);
  const Eigen::VectorXd phi = io::read_parameters_yaml(params.string(), names);
  // As control refuses it: a file whose digest no longer matches is not as identify wrote it
  // (a value or the flag edited), and the URDF would carry the edit as identified.
  const io::ParametersIntegrity integrity = io::parameters_integrity(params.string(), names);
  if (!integrity.intact && !options.not_accepted)
    throw UsageError(fmt::format("{}: the file is not as identify wrote it: {}; --not-accepted exports it anyway",
                                 params.string(), integrity.why));
  if (!integrity.intact)
    fmt::print(stderr, "export: {}: the file is not as identify wrote it: {} (exported anyway: --not-accepted)\n",
               params.string(), integrity.why);
  accepted = io::parameters_accepted(params.string());
  if (!accepted && !options.not_accepted)
    throw UsageError(params.string() +
                     ": the study's final audit did not accept these parameters (accepted: false); "
                     "--not-accepted exports them anyway");
  return phi;
}

// The prior the consistent set is nearest to along what the data barely sees: --prior (a file,
// or zero), else the twin's CAD truth, else robot.yaml's nominal parameters (a URDF's);
// `what` says which.
Eigen::VectorXd export_prior(const Common& common, const ExportOptions& options, const identify::ModelDescription& d,
                             std::string& what) {
  std::vector<std::string> standard_names;
  for (const auto& p : d.standard) standard_names.emplace_back(p.name);
  const int ns = static_cast<int>(d.standard.size());
  const auto twin_path = common.robot_dir() / "twin.yaml";
  if (options.prior == "zero") {
    what = "zero (the consistent set nearest 0)";
    return Eigen::VectorXd::Zero(ns);
  }
  if (!options.prior.empty()) {
    what = options.prior;
    return io::read_parameters_yaml(options.prior, standard_names);
  }
  if (std::filesystem::exists(twin_path)) {
    const twin::TwinConfig tc = twin::read_twin_config(twin_path, d.nq);
    what = twin_path.string() + " (CAD truth)";
    return twin::make_truth(full_model(common), tc).standard;
  }
  if (std::vector<double> nominal; nominal_standard_parameters(common, d.standard, nominal)) {
    // symoroc model's robot.yaml from a URDF: the URDF's own inertials.
    what = (common.robot_dir() / "robot.yaml").string() + " (nominal: the URDF's inertials)";
    return Eigen::Map<const Eigen::VectorXd>(nominal.data(), ns);
  }
  throw UsageError(
      fmt::format("robot '{}' has no twin.yaml to take a prior from: give --prior <standard-parameter "
                  "YAML> or --prior zero (see dynid export --help)",
                  common.robot));
}

// What the export says: the consistency, the files, and what a URDF consumer loses.
void print_export(const model_export::ModelExport& e, const model_export::ModelExportFiles& files,
                  const std::string& prior_what, const ExportOptions& options) {
  const identify::ConsistencyResult& r = e.consistency;
  if (e.nearest)
    fmt::print("WARNING: {}; exported the nearest base vector with a consistent set ({:.4g} away); {}\n", r.message,
               r.base_distance, e.cost);
  fmt::print("{}: {}; max |B s - phi| = {:.3g}, lambda_min = {:.4g}, prior {}\n",
             e.nearest ? "standard parameters of the nearest consistent base vector" : "consistent standard parameters",
             r.message, e.residual, r.lambda_min, prior_what);
  if (!options.urdf.empty()) fmt::print("urdf: {}\n", options.urdf);
  if (!options.mjcf.empty())
    fmt::print("mjcf: {} (rotor inertia as each joint's armature, FV as damping, FS as frictionloss)\n", options.mjcf);
  fmt::print("standard parameters: {}, {}\n", files.yaml.string(), files.csv.string());
  if (options.urdf.empty()) return;
  // The rotor inertia (a simulator's joint armature) has no URDF field.
  std::string rotor;
  for (std::size_t k = 0; k < e.description.names.size(); ++k)
    if (std::string(e.description.names[k].family) == "IA" && e.description.s(static_cast<Eigen::Index>(k)) != 0)
      rotor += fmt::format("{}{} {:.6g}", rotor.empty() ? "" : ", ", e.description.names[k].name,
                           e.description.s(static_cast<Eigen::Index>(k)));
  if (!rotor.empty())
    fmt::print(
        "rotor inertia has no URDF field: the URDF holds it only as comments, which URDF readers ignore; a "
        "simulator takes it from {}{}: {}\n",
        options.mjcf.empty() ? files.yaml.string() : options.mjcf,
        options.mjcf.empty() ? " (MuJoCo: each joint's armature; dynid export --mjcf writes it there)"
                             : " (each joint's armature)",
        rotor);
}

// --payload's file, of this robot.
payload::PayloadFile payload_file(const Common& common, const ExportOptions& options) {
  payload::PayloadFile f = payload::read_payload_yaml(options.payload);
  if (!f.robot.empty() && f.robot != common.robot)
    throw UsageError(fmt::format("{}: a payload of robot '{}', not {}", options.payload, f.robot, common.robot));
  return f;
}

// A payload.yaml's body as an MJCF body on its model frame, the flange at its recorded pose.
model_export::MjcfAttachment payload_body(const payload::PayloadFile& f) {
  model_export::MjcfAttachment a;
  a.name = "payload";
  a.frame = f.link;
  a.pose = f.flange_in_link;
  a.inertial.present = true;
  a.inertial.mass = f.payload.mass;
  a.inertial.com = f.payload.com;
  a.inertial.inertia = f.payload.inertia;
  return a;
}

// The URDF with a payload.yaml's body on its flange: into the user's URDF, on the flange link
// it names (a URDF tip link); into the model's URDF, on the payload's model frame's link, the
// flange at its recorded pose there.
std::string with_payload(const payload::PayloadFile& f, const ExportOptions& options,
                         const model_export::UrdfDescription& d, const std::string& urdf) {
  const bool frame = f.flange.rfind("frame ", 0) == 0;
  if (!options.into.empty() && frame)
    throw UsageError(
        fmt::format("{}: its flange is the model's {}, not a link of {}: dynid payload names a URDF "
                    "link as the flange for a robot symoroc model made from a URDF",
                    options.payload, f.flange, options.into));
  const std::string parent = options.into.empty() ? model_export::urdf_link_name(d, f.link) : f.flange;
  try {
    const std::string out = payload::urdf_with_payload(
        urdf, f.payload, parent, "payload", options.into.empty() ? f.flange_in_link : Eigen::Isometry3d::Identity());
    fmt::print("payload: {:.5g} kg on {} (from {})\n", f.payload.mass, parent, options.payload);
    return out;
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--payload {}: {}", options.payload, e.what()));
  }
}

}  // namespace export_detail

void run_export(const Common& common, const ExportOptions& options, const std::string& label) {
  // parent: the robot's full model (the fitting run's regression).
  const std::shared_ptr<const identify::IdentificationModel> model = identification_model(common, label);
  const std::shared_ptr<const identify::IdentificationModel> parent = identification_model(common, "full");
  const identify::ModelDescription& d = model->description();
  if (const std::vector<std::string> effects = identify::effect_parameter_names(d); !effects.empty())
    throw UsageError(
        fmt::format("model '{}' has model-gap effect parameters ({}), which no URDF or MJCF field carries: export a "
                    "study of a model without effects",
                    d.variant, fmt::join(effects, ", ")));
  if (!model->supports_physical_consistency())
    throw UsageError(fmt::format("model '{}' has no physical consistency to export", d.variant));
  const std::filesystem::path params = std::filesystem::path(options.study) / "report" / "parameters.yaml";
  bool accepted = false;
  const Eigen::VectorXd phi = export_detail::read_study_parameters(common, options, d, params, accepted);
  model_export::ModelExportOptions eo;
  eo.prior = export_detail::export_prior(common, options, d, eo.prior_what);
  eo.study = options.study;
  eo.accepted = accepted;
  eo.margin = options.margin;
  eo.nearest = options.nearest;
  std::optional<export_detail::FittingRun> fitting;
  if (!options.data.empty()) {
    fitting = export_detail::fitting_run(*parent, params, options.data, options.trial);
    eo.base_metric_root = export_detail::torque_metric_root(fitting->reg);
  }
  eo.cost = [&](const Eigen::VectorXd& target, const Eigen::VectorXd& phi_consistent) {
    return fitting ? export_detail::torque_cost(*fitting, target, phi_consistent)
                   : std::string(
                         "--data <the study's dataset> measures the torque it costs on the fitting data (and takes "
                         "the nearest vector in that metric)");
  };
  const model_export::ModelExport e = model_export::export_model(*model, phi, eo);
  std::string urdf_text;
  if (options.urdf.empty()) {
    // MJCF only (--into needs --urdf: refused before the work)
  } else if (options.into.empty()) {
    urdf_text = model_export::urdf_text(e.description);
  } else {
    std::vector<std::string> notes;
    urdf_text = urdf_into(e.description, (common.robot_dir() / "robot.yaml").string(), options.into, notes);
    for (const auto& note : notes) fmt::print("{}\n", note);
  }
  std::vector<model_export::MjcfAttachment> attachments;
  if (!options.payload.empty()) {
    const payload::PayloadFile f = export_detail::payload_file(common, options);
    if (!options.urdf.empty()) urdf_text = export_detail::with_payload(f, options, e.description, urdf_text);
    attachments.push_back(export_detail::payload_body(f));
  }
  std::string mjcf_text;
  if (!options.mjcf.empty()) try {
      mjcf_text = model_export::mjcf_text(e.description, full_model(common).gravity(), attachments);
    } catch (const std::invalid_argument& x) {
      throw std::runtime_error(std::string("no MJCF written: ") + x.what());
    }
  // The standard parameters go beside the URDF, else beside the MJCF.
  const model_export::ModelExportFiles files = model_export::write_model_export(
      e, options.urdf.empty() ? options.mjcf : options.urdf, options.urdf.empty() ? mjcf_text : urdf_text);
  if (!options.urdf.empty() && !options.mjcf.empty()) io::write_file_atomically(options.mjcf, mjcf_text);
  export_detail::print_export(e, files, eo.prior_what, options);
}

void add_export_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = app.add_subcommand(
      "export",
      "A study's accepted base parameters as a URDF with physically consistent inertials (one link per modified-DH "
      "frame of the model), joint damping/friction from FV/FS, and the standard parameters as YAML and CSV");
  add_robot_options(cmd, common);
  cmd->add_option("--study", o->study, "Study folder of dynid identify (reads report/parameters.yaml)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--urdf", o->urdf, "URDF file to write; <stem>.standard.yaml and <stem>.standard.csv go beside it");
  cmd->add_option("--mjcf", o->mjcf,
                  "MuJoCo model (MJCF) to write, with rotor inertia as armature (docs/mjcf.md); "
                  "without --urdf the .standard.yaml/.csv go beside it");
  cmd->add_option("--model", o->model, "Model the study identified (checked; default: the study's own)");
  cmd->add_option("--into", o->into,
                  "The robot's own URDF (the one symoroc model read): --urdf is then that file with "
                  "the identified inertials and joint dynamics, everything else unchanged")
      ->check(CLI::ExistingFile);
  cmd->add_option("--prior", o->prior,
                  "Standard parameters the consistent set is drawn towards where the base parameters leave it free: "
                  "a YAML with every standard parameter (e.g. an earlier export's .standard.yaml), or `zero` "
                  "(the consistent set nearest 0: smallest masses and inertias, a generic choice with no physical "
                  "meaning for the unidentifiable part). Default: the CAD truth of robots/<robot>/twin.yaml, else "
                  "robot.yaml's nominal parameters (a URDF's); a robot with neither needs --prior");
  cmd->add_option("--margin", o->margin,
                  "Strictness of the consistency: every link's pseudo-inertia >= margin I "
                  "(kg m^2 / kg; 0 allows singular links)")
      ->check(numbers::non_negative(1, ">= 0 and <= 1"))
      ->capture_default_str();
  cmd->add_flag("--not-accepted", o->not_accepted,
                "Export even when the study's final audit did not accept its "
                "parameters, or the file is not as identify wrote it (edited)");
  cmd->add_option("--data", o->data,
                  "The study's dataset: when no consistent set reproduces the accepted parameters, "
                  "the nearest consistent vector is the one that changes the predicted torque on "
                  "the study's fitting run least, and that change is reported")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--trial", o->trial, "Which trial of the fitting run (with --data)")
      ->check(numbers::count(1, 1e6))
      ->capture_default_str();
  cmd->add_flag("--nearest", o->nearest,
                "When no consistent set reproduces the accepted base parameters, export the "
                "consistent set of the nearest base vector that has one (said in the files) "
                "instead of failing");
  cmd->add_option("--payload", o->payload,
                  "A payload.yaml of dynid payload: the payload as a link on a fixed joint at its flange")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--force", o->force, "Overwrite the URDF, the MJCF and the .standard.yaml/.csv when they exist");
  cmd->callback([&common, o] {
    // One export to a URDF at a time (its own lock file beside it, held to the end: two at once
    // both passed the check below, and the last writer won), and, like import and control, an
    // existing file is replaced only when the user says so, before any work is done.
    if (o->urdf.empty() && o->mjcf.empty()) throw UsageError("say what to write: --urdf file, --mjcf file, or both");
    if (o->urdf.empty() && !o->into.empty()) throw UsageError("--into writes a URDF: give --urdf too");
    const std::filesystem::path target(o->urdf.empty() ? o->mjcf : o->urdf);
    const io::FolderLock lock(target.parent_path().empty() ? std::filesystem::path(".") : target.parent_path(),
                              "dynid export", "." + target.filename().string() + ".lock", /*remove_when_done=*/true);
    std::filesystem::path stem = target;
    stem.replace_extension();
    std::vector<std::filesystem::path> outputs{target, std::filesystem::path(stem.string() + ".standard.yaml"),
                                               std::filesystem::path(stem.string() + ".standard.csv")};
    if (!o->urdf.empty() && !o->mjcf.empty()) outputs.emplace_back(o->mjcf);
    for (const std::filesystem::path& f : outputs) {
      if (std::filesystem::is_directory(f))
        throw UsageError(fmt::format("{} is a directory: --urdf and --mjcf name the files to write", f.string()));
      if (std::filesystem::exists(f) && !o->force)
        throw UsageError(fmt::format(
            "{} exists: dynid export does not overwrite it; choose another --urdf or --mjcf, or --force", f.string()));
    }
    const std::string file = (std::filesystem::path(o->study) / "report" / "parameters.yaml").string();
    const std::string label = study_model(file);
    if (!o->model.empty() && o->model != label)
      throw UsageError(fmt::format("--model {}, but {} holds the parameters of model {}", o->model, file, label));
    run_export(common, *o, label);
  });
}

}  // namespace symoro::dynid
