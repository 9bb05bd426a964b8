// dynid import: logs exported by a robot's own controller (CSV, ';' or whitespace, any rate)
// into a dataset folder the other commands read: one project log per input, import.yaml (the
// mapping used) and dataset.yaml, with an optional fitting / held-out split recorded there.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "dynid_import.hpp"
#include "dynid_robots.hpp"
#include "dynid_numbers.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/import_bag.hpp"

namespace symoro::dynid {

namespace {

constexpr const char* selector_help =
    "header name, pattern ('pos_*': joint 1..n, 'pos_%': 0..n-1, '{name}_pos': the robot's joint names), "
    "list 'a,b,c', or 1-based positions ('2-8', '2,4,6')";

}  // namespace

namespace import_detail {

// The command line's settings over the mapping file's (or the defaults).
io::ImportMapping mapping_of(const ImportOptions& options) {
  io::ImportMapping m = options.mapping.empty() ? io::ImportMapping{} : io::read_import_mapping(options.mapping);
  io::apply_settings(m,
                     {options.time, options.q, options.qd, options.tau, options.q_ref, options.qd_ref, options.qdd_ref,
                      options.time_unit, options.angle, options.header, options.delimiter, options.torque_scale});
  if (m.time.empty() || m.q.empty() || m.tau.empty())
    throw UsageError("say which columns hold time, q and tau: --time, --q, --tau, or --mapping map.yaml");
  return m;
}

// The bag settings: the command line's, the torque constants from it or robot.yaml.
io::BagSettings bag_settings_of(const Common& common, const ImportOptions& options, std::size_t joints) {
  try {
    return io::bag_settings(options.topic, options.stamp, options.effort, options.torque_constants, joints,
                            common.robot_dir() / "robot.yaml");
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--effort, --torque-constant: ") + e.what());
  }
}

}  // namespace import_detail

void run_import(const Common& common, const ImportOptions& options, const std::vector<JointInfo>& joints) {
  io::DatasetImport di;
  di.target = io::import_target(common.robot, joints);
  const bool text =
      std::any_of(options.inputs.begin(), options.inputs.end(), [](const std::string& i) { return !io::is_bag(i); });
  if (text) di.mapping = import_detail::mapping_of(options);
  di.bag = import_detail::bag_settings_of(common, options, joints.size());
  di.split = options.split;
  di.allow_implausible = options.allow_implausible;
  if (!options.names.empty() && options.names.size() != options.inputs.size())
    throw UsageError(fmt::format("--name: {} names for {} input files", options.names.size(), options.inputs.size()));
  for (const std::string& h : options.heldout)
    if (std::find(options.inputs.begin(), options.inputs.end(), h) == options.inputs.end())
      throw UsageError(fmt::format("--heldout {}: not one of the input files", h));
  for (std::size_t i = 0; i < options.inputs.size(); ++i)
    di.inputs.push_back(
        {options.inputs[i], options.names.empty() ? "" : options.names[i],
         std::find(options.heldout.begin(), options.heldout.end(), options.inputs[i]) != options.heldout.end()});
  const io::DatasetImportResult r = io::import_dataset(options.out, di);
  for (const io::ImportedLog& l : r.logs) {
    const io::Log& log = l.log;
    fmt::print(
        "{}: {} rows -> {}.csv: {} samples over {:.3f} s, sample time {:g} ms (median), {} stale rows kept, "
        "{} duplicates dropped, velocity {}\n",
        l.input.string(), l.rows, log.meta.trajectory, log.samples(), log.time[log.samples() - 1] - log.time[0],
        log.meta.sample_time * 1e3, l.stale_lines.size(), l.duplicate_lines.size(),
        log.meta.velocity == io::Velocity::measured ? "measured" : "differentiated from q");
    for (const std::string& r : l.remarks) fmt::print("  {}\n", r);
    if (!l.stale_lines.empty())
      fmt::print("  stale rows (same state as the row before, new stamp) on lines {}{}\n", l.stale_lines.front(),
                 l.stale_lines.size() > 1 ? fmt::format(" .. {}", l.stale_lines.back()) : "");
  }
  for (const auto& run : r.runs) {
    fmt::print("run {} (family {}): {}", run.trajectory, run.family, run.file.filename().string());
    if (std::isfinite(run.window_start) || std::isfinite(run.window_end))
      fmt::print(", window [{:.6g}, {:.6g}) s", run.window_start, run.window_end);
    fmt::print("\n");
  }
  fmt::print("dataset: {} (mapping kept in import.yaml)\n", r.dataset.string());
}

void add_import_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ImportOptions>();
  auto* cmd = app.add_subcommand("import",
                                 "Import a controller's exported logs (CSV, ';' or whitespace text) or ROS 2 bags "
                                 "(MCAP) into a dataset folder");
  cmd->footer(
      "Examples:\n"
      "  dynid import --robot crane_x7 -o data/ run1.csv run2.csv --time t --time-unit ms \\\n"
      "      --q 'pos_*' --qd 'vel_*' --tau 'eff_*' --angle deg --split 0.7\n"
      "  dynid import --robot crane_x7 -o data/ --mapping map.yaml --heldout check.txt long.txt check.txt\n"
      "  dynid import --robot planar2r -o data/ log.txt --time 1 --q 2-3 --tau 4-5   # no header row\n"
      "  dynid import --robot my_arm -o data/ rosbag2_2026_11_29/ --split 0.7          # a ROS 2 bag folder\n"
      "  dynid import --robot crane_x7 -o data/ run.mcap --effort current --topic /crane_x7/joint_states\n"
      "A mapping file has the same keys: time, q, qd, tau, q_ref, qd_ref, qdd_ref, units: {time, angle,\n"
      "torque_scale}, header, delimiter (docs/dataset.md). Repeated rows with a new stamp (stale reads) are\n"
      "kept and counted; a repeated stamp with the same values is dropped; without --qd the velocity is\n"
      "differentiated from q and the log says so.\n"
      "A ROS 2 bag (an .mcap file, or the folder with metadata.yaml) is read for sensor_msgs/msg/JointState on\n"
      "--topic; joints are matched by name (docs/dataset.md, ROS 2 bags).");
  cmd->add_option("inputs", o->inputs, "Exported files or ROS 2 bags (.mcap, bag folders), one run each")
      ->required()
      ->check(CLI::ExistingPath);
  add_robot_options(cmd, common, "Robot folder name under robots/ (its joints set n)");
  cmd->add_option("-o,--out", o->out, "Dataset folder to create (existing files are never replaced)")->required();
  cmd->add_option("--mapping", o->mapping, "Mapping file (YAML); the options below override it")
      ->check(CLI::ExistingFile);
  cmd->add_option("--time", o->time, std::string("Time column: ") + selector_help);
  cmd->add_option("--q", o->q, std::string("Position columns (n): ") + selector_help);
  cmd->add_option("--qd", o->qd, "Velocity columns (n); without them qd is differentiated from q");
  cmd->add_option("--tau", o->tau, "Torque columns (n)");
  cmd->add_option("--q-ref", o->q_ref, "Reference position columns (with --qd-ref and --qdd-ref)");
  cmd->add_option("--qd-ref", o->qd_ref, "Reference velocity columns");
  cmd->add_option("--qdd-ref", o->qdd_ref, "Reference acceleration columns");
  cmd->add_option("--time-unit", o->time_unit, "Unit of the time column (default s)")
      ->check(CLI::IsMember({"s", "ms", "us", "ns"}));
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
  cmd->add_option("--topic", o->topic, "Bags: the sensor_msgs/msg/JointState topic (default /joint_states)");
  cmd->add_option("--stamp", o->stamp,
                  "Bags: time from the messages' header.stamp (default) or the recorder's receive time")
      ->check(CLI::IsMember({"header", "receive"}));
  cmd->add_option("--effort", o->effort,
                  "Bags: JointState.effort is joint torque (default) or motor current in A, times the torque "
                  "constants")
      ->check(CLI::IsMember({"torque", "current"}));
  cmd->add_option("--torque-constant", o->torque_constants,
                  "With --effort current: N m/A, one for all joints or one per joint (default: robot.yaml's "
                  "torque_constant of each joint)")
      ->delimiter(',')
      ->check(numbers::positive(1e6, "> 0"));
  cmd->add_option("--name", o->names, "Run names, one per input (default: the file names' stems)")->delimiter(',');
  cmd->add_option("--heldout", o->heldout, "Inputs held out whole (family V)")->delimiter(',');
  cmd->callback([&common, o] { run_import(common, *o, robot_model(common, "").joints()); });
}

}  // namespace symoro::dynid
