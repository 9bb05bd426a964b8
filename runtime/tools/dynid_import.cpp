// dynid import: logs exported by a robot's own controller (CSV, ';' or whitespace, any rate)
// into a dataset folder the other commands read: one project log per input, import.yaml (the
// mapping used) and dataset.yaml, with an optional fitting / held-out split recorded there.
#include <string>

#include <CLI/CLI.hpp>

#include "dynid_import.hpp"
#include "dynid_numbers.hpp"

namespace symoro::dynid {

namespace {

constexpr const char* selector_help =
    "header name, pattern ('pos_*': joint 1..n, 'pos_%': 0..n-1, '{name}_pos': the robot's joint names), "
    "list 'a,b,c', or 1-based positions ('2-8', '2,4,6')";

}  // namespace

void add_import_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ImportOptions>();
  auto* cmd = app.add_subcommand("import", "Import a controller's exported logs (CSV, ';' or whitespace text) into a "
                                           "dataset folder");
  cmd->footer(
      "Examples:\n"
      "  dynid import --robot crane_x7 -o data/ run1.csv run2.csv --time t --time-unit ms \\\n"
      "      --q 'pos_*' --qd 'vel_*' --tau 'eff_*' --angle deg --split 0.7\n"
      "  dynid import --robot crane_x7 -o data/ --mapping map.yaml --heldout check.txt long.txt check.txt\n"
      "  dynid import --robot planar2r -o data/ log.txt --time 1 --q 2-3 --tau 4-5   # no header row\n"
      "A mapping file has the same keys: time, q, qd, tau, q_ref, qd_ref, qdd_ref, units: {time, angle,\n"
      "torque_scale}, header, delimiter (docs/dataset.md). Repeated rows with a new stamp (stale reads) are\n"
      "kept and counted; a repeated stamp with the same values is dropped; without --qd the velocity is\n"
      "differentiated from q and the log says so.");
  cmd->add_option("inputs", o->inputs, "Exported files, one run each")->required()->check(CLI::ExistingFile);
  add_robot_options(cmd, common, "Robot folder name under robots/ (its joints set n)");
  cmd->add_option("-o,--out", o->out, "Dataset folder to create (existing files are never replaced)")->required();
  cmd->add_option("--mapping", o->mapping, "Mapping file (YAML); the options below override it")->check(CLI::ExistingFile);
  cmd->add_option("--time", o->time, std::string("Time column: ") + selector_help);
  cmd->add_option("--q", o->q, std::string("Position columns (n): ") + selector_help);
  cmd->add_option("--qd", o->qd, "Velocity columns (n); without them qd is differentiated from q");
  cmd->add_option("--tau", o->tau, "Torque columns (n)");
  cmd->add_option("--q-ref", o->q_ref, "Reference position columns (with --qd-ref and --qdd-ref)");
  cmd->add_option("--qd-ref", o->qd_ref, "Reference velocity columns");
  cmd->add_option("--qdd-ref", o->qdd_ref, "Reference acceleration columns");
  cmd->add_option("--time-unit", o->time_unit, "Unit of the time column (default s)")->check(CLI::IsMember({"s", "ms", "us", "ns"}));
  cmd->add_option("--angle", o->angle, "Unit of angles (and angle/s, angle/s^2; prismatic joints stay in m)")
      ->check(CLI::IsMember({"rad", "deg"}));
  cmd->add_option("--torque-scale", o->torque_scale, "Factor from the torque columns to N m (e.g. 0.001 for mN m)")
      ->check(numbers::positive(1e6, "> 0 and <= 1e6"));
  cmd->add_option("--header", o->header, "Header row (default auto: a first row with a non-number)")
      ->check(CLI::IsMember({"auto", "yes", "no"}));
  cmd->add_option("--delimiter", o->delimiter, "Field separator (default auto: ',' then ';' then blanks)")
      ->check(CLI::IsMember({"auto", "comma", "semicolon", "whitespace"}));
  cmd->add_option("--split,--fit", o->split,
                  "Fit on the first fraction of each run's time, hold out the rest as <name>_heldout (family V); "
                  "recorded in dataset.yaml")
      ->check(numbers::checked(0, 1, false, false, "a fraction from 0 (no split) to 1"));
  cmd->add_flag("--allow-implausible", o->allow_implausible,
               "Import positions far beyond the robot's joint limits, or a median time step outside "
               "[0.1 ms, 0.5 s] (refused by default: a unit declared wrong)");
  cmd->add_option("--name", o->names, "Run names, one per input (default: the file names' stems)")->delimiter(',');
  cmd->add_option("--heldout", o->heldout, "Inputs held out whole (family V)")->delimiter(',');
  cmd->callback([&common, o] { import_units().robot(common)(common, *o); });
}

}  // namespace symoro::dynid
