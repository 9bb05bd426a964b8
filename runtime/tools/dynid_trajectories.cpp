// dynid trajectories: list the robot's designed identification trajectories or write them as
// reference files (time, q_ref, qd_ref, qdd_ref at the control period).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <CLI/CLI.hpp>
#include <Eigen/SVD>
#include <fmt/format.h>

#include "dynid_numbers.hpp"
#include "dynid_robots.hpp"
#include "dynid_trajectories.hpp"
#include "symoro/excitation/quality.hpp"
#include "symoro/study/options.hpp"
#include "symoro/io/log.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::dynid {

RegressorFactor RegressorFactor::of(const Eigen::MatrixXd& W) { return {excitation::triangular_factor(W), W.rows()}; }

RegressorFactor RegressorFactor::stacked(const std::vector<RegressorFactor>& parts) {
  Eigen::Index rows = 0, factor_rows = 0;
  for (const auto& f : parts) rows += f.rows, factor_rows += f.R.rows();
  Eigen::MatrixXd Rs(factor_rows, parts.empty() ? 0 : parts.front().R.cols());
  Eigen::Index at = 0;
  for (const auto& f : parts) {
    Rs.middleRows(at, f.R.rows()) = f.R;
    at += f.R.rows();
  }
  return {excitation::triangular_factor(Rs), rows};
}

double log_det_per_sample(const RegressorFactor& f, int joints) {
  // log det (W'W / N) = 2 sum log sigma_i(R) - p log N; -inf when R is numerically singular.
  const Eigen::Index p = f.R.cols();
  const double samples = static_cast<double>(f.rows / std::max(1, joints));
  if (f.R.rows() < p || p == 0) return -std::numeric_limits<double>::infinity();
  const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(f.R).singularValues();
  if (excitation::numerically_singular(sigma)) return -std::numeric_limits<double>::infinity();
  return 2 * sigma.array().log().sum() - static_cast<double>(p) * std::log(samples);
}

Eigen::MatrixXd reference_regressor(const identify::IdentificationModel& model, const std::string& file,
                                    const TrajectoryOptions& options, double& duration) {
  const identify::ModelDescription& d = model.description();
  const double interval = options.interval_ms / 1000;
  const io::Log log = io::read_log(file);
  const auto joints = log.has_references() ? log.q_ref.cols() : log.joints();
  if (joints != d.nq) throw UsageError(fmt::format("--compare {}: {} joints, the model {}", file, joints, d.nq));
  duration = log.time(log.samples() - 1) - log.time(0);
  if (log.has_references()) {
    const auto period = log.meta.sample_time > 0 ? log.meta.sample_time : options.period;
    return model.stack_regression(excitation::reference_samples(trajectory::sampled_reference(log, period), interval))
        .W;
  }
  return model.stack_regression(preprocess::preprocess(log, interval, study::StudyOptions{}.preprocess)).W;
}

Eigen::MatrixXd trajectory_regressor(const identify::IdentificationModel& model, const trajectory::Trajectory& t,
                                     const TrajectoryOptions& options) {
  return model
      .stack_regression(
          excitation::reference_samples(trajectory::sample(t, options.period), options.interval_ms / 1000))
      .W;
}

std::string trajectory_quality_table(const Common& common, const std::vector<trajectory::Trajectory>& trajectories,
                                     const TrajectoryOptions& options, const std::string& model_name) {
  const auto model = identification_model(common, model_name);
  std::string out;
  const identify::ModelDescription& d = model->description();
  out += fmt::format(
      "excitation of {} model {} ({} base parameters) at {:.0f} ms: kappa of W, kappa of W and log det of W'W with "
      "unit columns (<= 0, 0 when the columns are orthogonal), log det of W'W / N per sample (the model's SI "
      "units, N samples: larger is more information per sample), the weakest direction's largest components\n",
      common.robot, d.variant.empty() ? "full" : d.variant, d.np, options.interval_ms);
  out += fmt::format("{:<6} {:<4} {:>8} {:>11} {:>11} {:>10} {:>10}  {}\n", "name", "fam", "duration", "kappa",
                     "kappa_scl", "logdet_scl", "logdet/N", "weakest");
  auto row = [&](const std::string& name, const std::string& family, double duration, const RegressorFactor& f) {
    const excitation::ExcitationQuality q = excitation::excitation_quality_of_factor(f.R, f.rows, d.parameters);
    std::string weakest;
    if (!q.unexcited.empty())
      weakest = fmt::format("{} parameters not excited (e.g. {})", q.unexcited.size(), q.unexcited.front());
    for (const auto& [p, v] : q.weakest) weakest += fmt::format("{}{} {:+.2f}", weakest.empty() ? "" : ", ", p, v);
    out += fmt::format("{:<6} {:<4} {:>7.1f}s {:>11.4g} {:>11.4g} {:>10.3f} {:>10.2f}  {}\n", name, family, duration,
                       q.kappa, q.kappa_scaled, q.log_det_scaled, log_det_per_sample(f, d.nq), weakest);
  };
  std::vector<RegressorFactor> factors;
  double total = 0;
  for (const auto& t : trajectories) {
    factors.push_back(RegressorFactor::of(trajectory_regressor(*model, t, options)));
    row(t.name, t.family, t.duration(), factors.back());
    total += t.duration();
  }
  // The reference motions the user compares with (not in the design's whole below).
  for (const auto& file : options.compare) {
    double duration = 0;
    const RegressorFactor f = RegressorFactor::of(reference_regressor(*model, file, options, duration));
    row(std::filesystem::path(file).stem().string(), "ref", duration, f);
  }
  // The design as a whole: all its trajectories stacked.
  if (trajectories.size() > 1) row("all", "", total, RegressorFactor::stacked(factors));
  return out;
}

void run_trajectories(const Common& common, const TrajectoryOptions& options) {
  const robot::ModelHandle full = full_model(common);
  const auto design = read_design(common, full.joints());
  const std::vector<std::string> names = options.only.empty() ? design.names() : options.only;
  std::vector<std::string> joint_names;
  for (const auto& j : full.joints()) joint_names.push_back(j.name);
  if (options.out.empty() && options.quality) {
    std::vector<trajectory::Trajectory> all;
    for (const auto& name : names) all.push_back(design.build(name));
    fmt::print("{}", trajectory_quality_table(common, all, options));
    return;
  }
  if (options.out.empty()) {
    fmt::print("{:<6} {:<4} {:>9}  {}\n", "name", "fam", "duration", "description");
    double total = 0;
    for (const auto& name : names) {
      const auto t = design.build(name);
      total += t.duration();
      fmt::print("{:<6} {:<4} {:>8.1f}s  {}\n", t.name, t.family, t.duration(), t.description);
    }
    fmt::print("{} trajectories, {:.1f} s in all\n", names.size(), total);
    return;
  }
  std::filesystem::create_directories(options.out);
  Progress progress(static_cast<int>(names.size()), "reference");
  for (const auto& name : names) {
    const auto t = design.build(name);
    io::write_log(std::filesystem::path(options.out) / (name + ".csv"),
                  trajectory::reference_log(t, options.period, common.robot, joint_names));
    progress.done(name, fmt::format("{:.1f} s", t.duration()));
  }
}

void add_trajectory_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<TrajectoryOptions>();
  auto* cmd =
      app.add_subcommand("trajectories", "List the identification trajectories, or write them as reference files");
  add_robot_options(cmd, common);
  cmd->add_option("--design", common.design,
                  "A trajectory design file (e.g. dynid excite's) instead of robots/<robot>/trajectories.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->out, "Write <name>.csv and <name>.meta.yaml here (default: list only)");
  cmd->add_option("--only", o->only, "Only these trajectories");
  // At least 0.1 ms (10 kHz): --period 1e-9 ran out of memory, 1e-6 wrote 7.9 GB.
  cmd->add_option("--period", o->period, "Sample period of the reference files, s")
      ->check(numbers::checked(1e-4, 10, false, false, "from 0.0001 to 10 s"));
  cmd->add_flag("--quality", o->quality,
                "Print each trajectory's excitation of the robot's identified model: kappa, "
                "kappa and log det with unit columns, the weakest direction");
  cmd->add_option("--interval", o->interval_ms, "Sampling interval of --quality, ms (as in identification)")
      ->check(numbers::interval_ms())
      ->capture_default_str();
  cmd->add_option("--compare", o->compare,
                  "With --quality: logs of reference motions (e.g. a published trajectory's "
                  "recording, imported) rated beside the design")
      ->check(CLI::ExistingFile);
  cmd->callback([&common, o] { run_trajectories(common, *o); });
}

}  // namespace symoro::dynid
