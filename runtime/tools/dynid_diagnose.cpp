// dynid diagnose: which effect is the identified model missing? Fits the model's structure with
// every candidate effect on the fitting trajectories, keeps those that are significant and
// improve the held-out ones (forward stepwise), localizes the residual before and after, and
// writes a report and the robot.yaml variant that compiles the effects in (--apply adds it).
#include <CLI/CLI.hpp>

#include <fmt/format.h>

#include "dynid_diagnose.hpp"
#include "dynid_robots.hpp"
#include "dynid_numbers.hpp"
#include "symoro/diagnose/dataset_diagnosis.hpp"
#include "symoro/diagnose/effects.hpp"
#include "symoro/diagnose/loaded_model.hpp"

namespace symoro::dynid {

namespace {

// --only's help: the diagnosis's effects, and the effect table's rows it looks for when named.
std::string only_help() {
  std::string own, asked;
  for (const auto& e : symoro::diagnose::effect_catalogue()) {
    std::string& list = symoro::diagnose::only_when_named(e.kind) ? asked : own;
    list += (list.empty() ? "" : ", ") + std::string(e.name);
  }
  return "Only these effects (" + own + ")" + (asked.empty() ? "" : "; these only when named: " + asked);
}

diagnose::DatasetDiagnosisOptions library_options(const Common& common, const DiagnoseOptions& options) {
  diagnose::DatasetDiagnosisOptions d;
  d.data = options.data;
  d.out = options.out;
  d.robot_dir = common.robot_dir();
  d.train = options.train;
  d.heldout = options.heldout;
  d.trial = options.trial;
  d.interval = options.interval_ms / 1000;
  d.cutoff = options.cutoff;
  d.only = options.only;
  d.alpha = options.alpha;
  d.min_heldout_gain = options.min_gain;
  d.min_effect_torque = options.min_torque;
  d.backlash = !options.no_backlash;
  d.params = options.params;
  d.variant = options.variant;
  return d;
}

}  // namespace

void run_diagnose(const Common& common, const DiagnoseOptions& options, const diagnose::DiagnosisModel& model) {
  diagnose::DatasetDiagnosisOptions d = library_options(common, options);
  d.say = [](const std::string& line) { fmt::print("{}\n", line); };
  try {
    const diagnose::DatasetDiagnosis r = diagnose::diagnose_dataset(model, d);
    if (options.apply.empty()) return;
    const auto yaml = common.robot_dir() / "robot.yaml";
    diagnose::add_variant_to_robot_yaml(yaml, r.variant_name, r.variant_yaml);
    // A robot compiled into dynid needs its code regenerated; any other is compiled again from
    // its folder by the next command that uses it.
    if (compiled_robot(common))
      fmt::print(
          "added variant '{}' to {}; regenerate (symoroc generate {} -o generated) and rebuild, then "
          "dynid identify --model {}\n",
          r.variant_name, yaml.string(), common.robot_dir().string(), r.variant_name);
    else
      fmt::print("added variant '{}' to {}; dynid identify --model {} compiles it\n", r.variant_name, yaml.string(),
                 r.variant_name);
  } catch (const diagnose::DiagnosisRequestError& e) {
    throw UsageError(e.what());
  }
}

void add_diagnose_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<DiagnoseOptions>();
  {  // the defaults are the library's, not written again here
    const diagnose::DatasetDiagnosisOptions d;
    o->trial = d.trial;
    o->interval_ms = d.interval * 1000;
    o->cutoff = d.cutoff;
    o->alpha = d.alpha;
    o->min_gain = d.min_heldout_gain;
    o->min_torque = d.min_effect_torque;
  }
  auto* cmd = app.add_subcommand("diagnose",
                                 "Model-gap diagnosis: which effects the identified model misses, how large, "
                                 "where the residual is; before/after report");
  add_robot_options(cmd, common);
  cmd->add_option("--data", o->data, "Dataset folder (dataset.yaml and logs)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--out", o->out, "Report folder")->required();
  cmd->add_option("--train", o->train,
                  "Runs the effects are fitted on (default: the dataset's runs of families other "
                  "than V, e.g. the fitting part of a split run)")
      ->delimiter(',');
  cmd->add_option("--heldout", o->heldout,
                  "Held-out runs that judge them (default: the dataset's family V, e.g. the "
                  "held-out part of a split run)")
      ->delimiter(',');
  cmd->add_option("--trial", o->trial, "Which trial of each trajectory")->check(numbers::count(1, 1e6));
  cmd->add_option("--interval", o->interval_ms, "Diagnosis grid, ms")->check(numbers::interval_ms());
  cmd->add_option("--cutoff", o->cutoff, "Low-pass on every column and the torque, Hz")
      ->check(numbers::positive(1e5, "> 0 and <= 1e5 Hz"));
  cmd->add_option("--only", o->only, only_help())->delimiter(',');
  cmd->add_option("--alpha", o->alpha, "Family-wise level of each step")
      ->check(numbers::checked(0, 0.5, true, false, "> 0 and <= 0.5"));
  cmd->add_option("--min-gain", o->min_gain, "Least relative fall of the held-out residual")
      ->check(numbers::non_negative(1, ">= 0 and <= 1"));
  cmd->add_option("--min-torque", o->min_torque, "Least effect torque that matters, N m")
      ->check(numbers::non_negative(1e6, ">= 0 and <= 1e6 N m"));
  cmd->add_flag("--no-backlash", o->no_backlash, "Skip the closed-loop high-band stage (backlash; simulates the twin)");
  cmd->add_option("--model", o->model,
                  "Model whose gap is diagnosed: a robot.yaml variant, or full (default: "
                  "robot.yaml's identified)");
  cmd->add_option("--params", o->params,
                  "An earlier identification (a study's report/parameters.yaml of this model): "
                  "hold its parameters and diagnose its gap, e.g. a payload added since; "
                  "default: refit the model's parameters with the effects")
      ->check(CLI::ExistingFile);
  cmd->add_option("--variant", o->variant, "Name of the variant to write (default: <identified>_diagnosed)");
  cmd->add_flag(
      "--apply", [o](std::int64_t) { o->apply = "yes"; }, "Add the variant to the robot's robot.yaml");
  cmd->callback([&common, o] {
    try {  // the options' own rules, before any work
      diagnose::check_request(library_options(common, *o));
    } catch (const diagnose::DiagnosisRequestError& e) {
      throw UsageError(e.what());
    }
    run_diagnose(common, *o, *diagnose::diagnosis_model(robot_model(common, o->model), full_model(common)));
  });
}

}  // namespace symoro::dynid
