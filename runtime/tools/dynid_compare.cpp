// dynid compare: the model-gap workflow's before/after. Two identification studies of one robot
// on the same data (dynid identify -o A, then with --model <diagnosed variant> -o B) set side by
// side on their held-out validation trajectories: rms torque error per trajectory and joint,
// the parameters the second model adds, and torque figures. Reads only the studies' folders,
// so neither model needs to be compiled into this dynid.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "dynid_common.hpp"
#include "dynid_numbers.hpp"
#include "symoro/diagnose/gap_report.hpp"
#include "symoro/study/validation_io.hpp"

namespace symoro::dynid {

namespace {

struct CompareOptions {
  std::string before, after, out, trajectory;
  std::vector<int> joints;  // 1-based on the command line
};

void run(const Common& common, const CompareOptions& options) {
  const study::StudyValidation before = study::read_validation(options.before);
  const study::StudyValidation after = study::read_validation(options.after);
  if (!common.robot.empty() && before.robot != common.robot)
    throw UsageError(fmt::format("--robot {}, but {} is a study of '{}'", common.robot, options.before, before.robot));
  diagnose::GapComparison c;
  try {
    c = diagnose::compare_studies(before, after);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("cannot compare {} with {}: {}", options.before, options.after, e.what()));
  }
  diagnose::GapReportOptions ro;
  try {
    ro = diagnose::gap_report_options(options.before, options.after, c, options.trajectory, options.joints);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--joints: {}", e.what()));
  }
  std::vector<std::filesystem::path> files;
  try {
    files = diagnose::write_gap_report(before, after, c, options.out, ro);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  for (const auto& t : c.trajectories)
    fmt::print("{} at {:g} ms: rms error {:.4f} -> {:.4f} N m\n", t.trajectory, t.interval * 1e3, t.rmse_before,
               t.rmse_after);
  fmt::print("held-out rms error: {:.4f} N m ({}) -> {:.4f} N m ({}), {:+.1f} %\n", c.rmse_before, c.before_model,
             c.rmse_after, c.after_model, 100 * (c.rmse_after - c.rmse_before) / c.rmse_before);
  fmt::print("report: {} ({} files)\n", (std::filesystem::path(options.out) / "gap.md").string(), files.size());
}

}  // namespace

void add_compare_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<CompareOptions>();
  auto* cmd = app.add_subcommand("compare",
                                 "Before/after report of two identification studies (e.g. the identified "
                                 "model and its diagnosed variant) on their held-out trajectories");
  cmd->add_option("--robot", common.robot, "Robot the studies are of (checked)");
  cmd->add_option("--before", o->before, "Study folder of the model before (dynid identify -o)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--after", o->after, "Study folder of the model after")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--out", o->out, "Report folder (gap.md, figures/)")->required();
  cmd->add_option("--trajectory", o->trajectory, "Held-out trajectory whose torques are plotted (default: the last)");
  cmd->add_option("--joints", o->joints, "Joints plotted, 1-based (default: the 3 whose error changed most)")
      ->delimiter(',')
      ->check(numbers::count(1, 64));
  cmd->callback([&common, o] { run(common, *o); });
}

}  // namespace symoro::dynid
