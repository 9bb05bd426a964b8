// dynid preprocess: a log through the preprocessing at the paper's intervals (or chosen ones):
// prints what was corrected, bridged, split and kept, and optionally writes the regression-
// ready samples as CSV (time, q, qd, qdd, tau per joint) for inspection.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "dynid_common.hpp"
#include "dynid_numbers.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::dynid {

namespace {

struct PreprocessOptions {
  std::vector<std::string> logs;
  std::vector<double> intervals_ms;
  std::string out;
  preprocess::Options options;
};

void write_samples(const std::filesystem::path& file, const preprocess::Samples& s) {
  const int n = static_cast<int>(s.q.cols());
  std::string text = "time";
  for (const char* g : {"q", "qd", "qdd", "tau"})
    for (int j = 1; j <= n; ++j) text += fmt::format(",{}{}", g, j);
  text += "\n";
  for (int k = 0; k < s.time.size(); ++k) {
    io::append_number(text, s.time(k));
    for (const Eigen::MatrixXd* m : {&s.q, &s.qd, &s.qdd, &s.tau})
      for (int j = 0; j < n; ++j) {
        text += ',';
        io::append_number(text, (*m)(k, j));
      }
    text += '\n';
  }
  io::write_file_atomically(file, text);
}

void run(const Common& common, const PreprocessOptions& cli) {
  std::vector<double> intervals;
  for (double ms : cli.intervals_ms) intervals.push_back(ms / 1000);
  if (intervals.empty()) intervals = preprocess::paper_intervals();
  for (const auto& path : cli.logs) {
    const io::Log log = io::read_log(path);
    if (!common.robot.empty() && log.meta.robot != common.robot)
      throw UsageError(fmt::format("{} is a log of robot '{}', not '{}'", path, log.meta.robot, common.robot));
    fmt::print("{}: {} samples, {:.1f} s, robot {}, trajectory {}\n", path, log.samples(),
               log.time(log.samples() - 1) - log.time(0), log.meta.robot, log.meta.trajectory);
    for (double interval : intervals) {
      const auto s = preprocess::preprocess(log, interval, cli.options);
      fmt::print("  {:>3.0f} ms: {}\n", interval * 1000, s.report.summary());
      if (!cli.out.empty()) {
        std::filesystem::create_directories(cli.out);
        const auto stem = std::filesystem::path(path).stem().string();
        write_samples(std::filesystem::path(cli.out) / fmt::format("{}_{:.0f}ms.csv", stem, interval * 1000), s);
      }
    }
  }
}

}  // namespace

void add_preprocess_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<PreprocessOptions>();
  auto* cmd =
      app.add_subcommand("preprocess", "Preprocess logs: time axis, zero-phase filter, derivatives, resampling");
  cmd->add_option("logs", o->logs, "Log CSV files")->required()->check(CLI::ExistingFile);
  cmd->add_option("--robot", common.robot, "Check that the logs are of this robot");
  cmd->add_option("--interval", o->intervals_ms, "Target intervals in ms (default: 10 20 40 80)")
      ->check(numbers::interval_ms());
  cmd->add_option("-o,--output", o->out, "Write <log>_<interval>ms.csv samples here");
  cmd->add_option("--cutoff", o->options.derivative_cutoff, "Low-pass cutoff for the derivatives, Hz")
      ->check(numbers::positive(1e5, "> 0 and <= 1e5 Hz"));
  cmd->add_option("--max-gap", o->options.max_gap, "Longest gap bridged by interpolation, s")
      ->check(numbers::non_negative(3600, ">= 0 and <= 3600 s"));
  cmd->add_option("--base-period", o->options.base_period,
                  "Grid period, s (default: each log's sample_time, else its median stamp interval)")
      ->check(numbers::positive(10, "> 0 and <= 10 s"));
  cmd->add_flag("!--keep-stale", o->options.drop_stale, "Keep stale rows (a state logged twice) in the regression");
  cmd->add_flag("--logged-velocity", o->options.use_logged_velocity,
                "qd from the log's qd (filtered), qdd from its differences, instead of both from q");
  cmd->callback([&common, o] { run(common, *o); });
}

}  // namespace symoro::dynid
