// dynid export --urdf: a study's accepted base parameters as a URDF of the robot with
// physically consistent inertials (identify/physical_consistency.hpp, identify/urdf_export.hpp),
// and the standard parameters beside it (<name>.standard.yaml, <name>.standard.csv).
#include <filesystem>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_export.hpp"
#include "dynid_numbers.hpp"

namespace symoro::dynid {

namespace {

// The model label the study was identified with (report/parameters.yaml `model:`; "" is the
// full model), to pick the instantiation when --model is not given.
std::string study_model(const std::string& file) {
  try {
    const YAML::Node root = YAML::LoadFile(file);
    // A study that produced no model says so here, before its (empty) parameter list is read
    // against the model's names.
    const YAML::Node list = root["parameters"];
    if (!list || !list.IsSequence() || list.size() == 0)
      throw UsageError(fmt::format("{}: the study has no model to export: no run produced a final vector, so there is "
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
  cmd->add_option("--urdf", o->urdf, "URDF file to write; <stem>.standard.yaml and <stem>.standard.csv go beside it")
      ->required();
  cmd->add_option("--model", o->model, "Model the study identified (checked; default: the study's own)");
  cmd->add_option("--into", o->into, "The robot's own URDF (the one symoroc model read): --urdf is then that file with "
                                     "the identified inertials and joint dynamics, everything else unchanged")
      ->check(CLI::ExistingFile);
  cmd->add_option("--prior", o->prior,
                  "Standard parameters the consistent set is drawn towards where the base parameters leave it free: "
                  "a YAML with every standard parameter (e.g. an earlier export's .standard.yaml), or `zero` "
                  "(the consistent set nearest 0: smallest masses and inertias, a generic choice with no physical "
                  "meaning for the unidentifiable part). Default: the CAD truth of robots/<robot>/twin.yaml, else "
                  "robot.yaml's nominal parameters (a URDF's); a robot with neither needs --prior");
  cmd->add_option("--margin", o->margin, "Strictness of the consistency: every link's pseudo-inertia >= margin I "
                                         "(kg m^2 / kg; 0 allows singular links)")
      ->check(numbers::non_negative(1, ">= 0 and <= 1"))
      ->capture_default_str();
  cmd->add_flag("--not-accepted", o->not_accepted, "Export even when the study's final audit did not accept its "
                                                   "parameters");
  cmd->add_option("--data", o->data, "The study's dataset: when no consistent set reproduces the accepted parameters, "
                                     "the nearest consistent vector is the one that changes the predicted torque on "
                                     "the study's fitting run least, and that change is reported")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--trial", o->trial, "Which trial of the fitting run (with --data)")->check(numbers::count(1, 1e6))->capture_default_str();
  cmd->add_flag("--nearest", o->nearest, "When no consistent set reproduces the accepted base parameters, export the "
                                         "consistent set of the nearest base vector that has one (said in the files) "
                                         "instead of failing");
  cmd->add_flag("--force", o->force, "Overwrite the URDF and its .standard.yaml/.csv when they exist");
  cmd->callback([&common, o] {
    // Like import and control: an existing file is replaced only when the user says so, and
    // before any work is done.
    std::filesystem::path stem = o->urdf;
    stem.replace_extension();
    for (const std::filesystem::path& f : {std::filesystem::path(o->urdf), std::filesystem::path(stem.string() + ".standard.yaml"),
                                           std::filesystem::path(stem.string() + ".standard.csv")}) {
      if (std::filesystem::is_directory(f))
        throw UsageError(fmt::format("{} is a directory: --urdf names the file to write", f.string()));
      if (std::filesystem::exists(f) && !o->force)
        throw UsageError(fmt::format("{} exists: dynid export does not overwrite it; choose another --urdf, or --force",
                                     f.string()));
    }
    const std::string file = (std::filesystem::path(o->study) / "report" / "parameters.yaml").string();
    const std::string label = study_model(file);
    if (!o->model.empty() && o->model != label)
      throw UsageError(fmt::format("--model {}, but {} holds the parameters of model {}", o->model, file, label));
    export_units().model(common, label)(common, *o);
  });
}

}  // namespace symoro::dynid
