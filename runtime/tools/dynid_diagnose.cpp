// dynid diagnose: which effect is the identified model missing? Fits the model's structure with
// every candidate effect on the fitting trajectories, keeps those that are significant and
// improve the held-out ones (forward stepwise), localizes the residual before and after, and
// writes a report and the robot.yaml variant that compiles the effects in (--apply adds it).
#include <regex>

#include <CLI/CLI.hpp>

#include "dynid_diagnose.hpp"
#include "dynid_numbers.hpp"
#include "symoro/diagnose/effects.hpp"

namespace symoro::dynid {

void add_diagnose_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<DiagnoseOptions>();
  auto* cmd = app.add_subcommand("diagnose", "Model-gap diagnosis: which effects the identified model misses, how large, "
                                             "where the residual is; before/after report");
  add_robot_options(cmd, common);
  cmd->add_option("--data", o->data, "Dataset folder (dataset.yaml and logs)")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--out", o->out, "Report folder")->required();
  cmd->add_option("--train", o->train, "Runs the effects are fitted on (default: the dataset's runs of families other "
                                       "than V, e.g. the fitting part of a split run)")->delimiter(',');
  cmd->add_option("--heldout", o->heldout, "Held-out runs that judge them (default: the dataset's family V, e.g. the "
                                           "held-out part of a split run)")->delimiter(',');
  cmd->add_option("--trial", o->trial, "Which trial of each trajectory")->check(numbers::count(1, 1e6));
  cmd->add_option("--interval", o->interval_ms, "Diagnosis grid, ms")->check(numbers::interval_ms());
  cmd->add_option("--cutoff", o->cutoff, "Low-pass on every column and the torque, Hz")->check(numbers::positive(1e5, "> 0 and <= 1e5 Hz"));
  cmd->add_option("--only", o->only, "Only these effects (coulomb, stribeck, offset, viscous_asymmetry, "
                                     "position_harmonics, inertia_products, torque_constant, actuation_delay, backlash, payload)")
      ->delimiter(',');
  cmd->add_option("--alpha", o->alpha, "Family-wise level of each step")->check(numbers::checked(0, 0.5, true, false, "> 0 and <= 0.5"));
  cmd->add_option("--min-gain", o->min_gain, "Least relative fall of the held-out residual")->check(numbers::non_negative(1, ">= 0 and <= 1"));
  cmd->add_option("--min-torque", o->min_torque, "Least effect torque that matters, N m")->check(numbers::non_negative(1e6, ">= 0 and <= 1e6 N m"));
  cmd->add_flag("--no-backlash", o->no_backlash, "Skip the closed-loop high-band stage (backlash; simulates the twin)");
  cmd->add_option("--model", o->model, "Model whose gap is diagnosed: a robot.yaml variant, or full (default: "
                                       "robot.yaml's identified)");
  cmd->add_option("--params", o->params, "An earlier identification (a study's report/parameters.yaml of this model): "
                                         "hold its parameters and diagnose its gap, e.g. a payload added since; "
                                         "default: refit the model's parameters with the effects")
      ->check(CLI::ExistingFile);
  cmd->add_option("--variant", o->variant, "Name of the variant to write (default: <identified>_diagnosed)");
  cmd->add_flag("--apply", [o](std::int64_t) { o->apply = "yes"; }, "Add the variant to the robot's robot.yaml");
  cmd->callback([&common, o] {
    // symoroc's rule for variant names, checked before any work.
    static const std::regex lower_id("^[a-z][a-z0-9_]*$");
    if (!o->variant.empty() && (!std::regex_match(o->variant, lower_id) || o->variant == "full" || o->variant == "param"))
      throw UsageError("--variant '" + o->variant + "' must be a lower-case identifier other than 'full' and 'param' (symoroc's rule)");
    for (const auto& e : o->only) {
      diagnose::effect_kind(e);  // unknown names: a clear error first
      if (e == "payload" && o->params.empty())
        throw UsageError("--only payload needs --params: a refit absorbs a payload into the last link's parameters, "
                         "so it is judged against an earlier identification held fixed");
    }
    diagnose_units().model(common, o->model)(common, *o);
  });
}

}  // namespace symoro::dynid
