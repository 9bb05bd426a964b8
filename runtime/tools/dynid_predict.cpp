// dynid predict: a model's inverse-dynamics torque on a log's measured motion, beside the
// measured torque, with the RMSE per joint: to check a model on one's own logs (an
// identification's parameters, or the nominal ones symoroc model took from a URDF). q, qd and
// qdd come from the identification's own preprocessing (time axis, zero-phase filter,
// derivatives, the sampling interval), so the numbers compare with the study's. Compiled once:
// the model is the robot's IdentificationModel (symoro::<robot>_identification).
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_common.hpp"
#include "dynid_identify.hpp"
#include "dynid_robots.hpp"
#include "dynid_numbers.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/study/prediction.hpp"
#include "symoro/study/prediction_band.hpp"
#include "symoro/study/options.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::dynid {

namespace {

namespace fs = std::filesystem;

struct PredictOptions {
  std::string params = "nominal", model, input, out;
  std::string uncertainty;  // "" : report/uncertainty.yaml beside --params when it is there
  double band = 0.95;       // the band's level (0: none)
  double interval_ms = study::PredictionOptions{}.interval * 1000;
  double torque_delay_ms = study::PredictionOptions{}.torque_delay * 1000;
  bool torque_delay_given = false;  // else the parameters file's (fit_torque_delay)
  int trial = 1;
  bool force = false;
};

// The parameters' uncertainty for the bands: --uncertainty, else report/uncertainty.yaml beside
// --params (a study's); none for nominal parameters, --band 0, or a study without one.
std::optional<study::PredictionUncertainty> uncertainty_of(const PredictOptions& o,
                                                           const identify::ModelDescription& d) {
  if (o.band == 0 || (o.uncertainty.empty() && o.params == "nominal")) return std::nullopt;
  const fs::path file =
      o.uncertainty.empty() ? fs::path(o.params).parent_path() / "uncertainty.yaml" : fs::path(o.uncertainty);
  if (o.uncertainty.empty() && !fs::exists(file)) return std::nullopt;
  std::vector<std::string> names;
  for (const auto& p : d.parameters) names.push_back(p.name);
  return study::read_uncertainty_yaml(file.string(), names);
}

// The prediction of one log, its samples (and the band's half-width) written to `csv`.
study::Prediction predict_log(const io::Log& log, const identify::IdentificationModel& model,
                              const Eigen::VectorXd& phi, const PredictOptions& options, const fs::path& csv,
                              const std::optional<study::PredictionUncertainty>& u, Eigen::MatrixXd& band) {
  study::Prediction p = study::predict(log, model, phi, {options.interval_ms / 1000, options.torque_delay_ms / 1000});
  const preprocess::Samples& s = p.samples;
  const int n = static_cast<int>(s.tau.cols());
  const auto& joints = model.description().joints;
  std::vector<const char*> what{"q", "qd", "qdd", "tau", "tau_model"};
  std::vector<const Eigen::MatrixXd*> columns{&s.q, &s.qd, &s.qdd, &s.tau, &p.tau_model};
  band.resize(0, 0);
  if (u) {
    band = study::prediction_band(model, s, *u, options.band);
    what.push_back("tau_band");
    columns.push_back(&band);
  }
  std::string text = "time";
  for (const char* w : what)
    for (int j = 0; j < n; ++j) text += fmt::format(",{}_{}", w, joints[j].name);
  text += "\n";
  for (Eigen::Index k = 0; k < s.tau.rows(); ++k) {
    text += io::number_text(s.time(k));
    for (const Eigen::MatrixXd* m : columns)
      for (int j = 0; j < n; ++j) text += "," + io::number_text((*m)(k, j));
    text += "\n";
  }
  io::write_file_atomically(csv, text);
  return p;
}

void run(const Common& common, const PredictOptions& given) {
  PredictOptions options = given;
  const FitTiming timing = fit_torque_delay(
      options.params, options.torque_delay_given ? std::optional<double>(options.torque_delay_ms) : std::nullopt);
  options.torque_delay_ms = timing.torque_delay_ms;
  const auto model = identification_model(common, parameters_model(options.params, options.model));
  const identify::ModelDescription& d = model->description();
  const Eigen::VectorXd phi =
      parameters_phi(common, robot_model(common, d.variant.empty() ? "full" : d.variant), options.params);

  // What to predict: one log, or every run of a dataset's trial.
  const fs::path input(options.input);
  const std::vector<io::NamedLog> logs = io::read_input_logs(input, d.robot, d.nq, options.trial);
  if (logs.empty()) throw UsageError(fmt::format("{}: no run of trial {}", input.string(), options.trial));
  const fs::path out(options.out);
  const bool one = logs.size() == 1 && !fs::is_directory(input);
  std::vector<fs::path> files;
  for (const auto& l : logs) files.push_back(one ? out : out / (l.name + ".predicted.csv"));
  for (const auto& f : files)
    if (fs::exists(f) && !options.force)
      throw UsageError(f.string() + " exists: dynid predict does not overwrite it; choose another --out, or --force");
  if (!one) fs::create_directories(out);

  fmt::print(
      "{} model {} with {} parameters, at {:.0f} ms, torque delay {:g} ms ({}): RMSE of tau - tau_model (RMS of tau) "
      "per joint, N m\n",
      common.robot, d.variant.empty() ? "full" : d.variant,
      options.params == "nominal" ? "the nominal" : options.params, options.interval_ms, timing.torque_delay_ms,
      timing.why);
  const std::optional<study::PredictionUncertainty> u = uncertainty_of(options, d);
  Eigen::VectorXd sq = Eigen::VectorXd::Zero(d.nq), inside = sq;
  int total = 0;
  std::string raw_filter;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    Eigen::MatrixXd band;
    const study::Prediction p = predict_log(logs[i].log, *model, phi, options, files[i], u, band);
    const int samples = static_cast<int>(p.samples.tau.rows());
    std::string line = fmt::format("  {:<10} {:>6} samples:", logs[i].name, samples);
    for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.4f} ({:.3f})", p.rmse(j), p.rms(j));
    fmt::print("{}\n", line);
    line = fmt::format("  {:<10} {:>6} raw:    ", "", p.raw.samples);
    for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.4f}        ", p.raw.error.rmse_joint(j));
    fmt::print("{}\n", line);
    line = fmt::format("  {:<10} {:>6} floor:  ", "", "");
    for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.4f}        ", p.raw.floor_joint(j));
    fmt::print("{}\n", line);
    fmt::print(
        "  {:<10} {:>6} raw RMSE {:.4f} N m over all joints and samples, mean of the joints' RMSE {:.4f} N m; floor: "
        "the "
        "torque's own content above the cutoff, which no model of the filtered motion follows, mean {:.4f} N m\n",
        "", "", p.raw.error.rmse, p.raw.error.rmse_joint.mean(), p.raw.floor_joint.mean());
    if (p.samples.report.edge_samples > 0 || p.samples.report.context_rows > 0)
      fmt::print("  {:<10} {}\n", "", p.samples.report.summary());
    if (u) {
      const study::BandCoverage c = study::band_coverage(p.samples.tau, p.tau_model, band);
      line = fmt::format("  {:<10} {:>6} inside the {:g} % band:", "", "", 100 * options.band);
      for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.1f} %", 100 * c.joint(j));
      fmt::print("{} (all {:.1f} %)\n", line, 100 * c.all);
      inside += c.joint * samples;
    }
    if (i + 1 == logs.size()) raw_filter = p.raw.filter;
    sq += p.rmse.cwiseAbs2() * samples;
    total += samples;
  }
  if (logs.size() > 1) {
    std::string line = fmt::format("  {:<10} {:>6} samples:", "all", total);
    for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.4f}", std::sqrt(sq(j) / total));
    fmt::print("{}\n", line);
  }
  if (u && logs.size() > 1) {
    std::string line = fmt::format("  {:<10} {:>6} inside the {:g} % band:", "all", total, 100 * options.band);
    for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.1f} %", 100 * inside(j) / total);
    fmt::print("{} (all {:.1f} %)\n", line, 100 * inside.sum() / total / d.nq);
  }
  if (u)
    fmt::print(
        "band: the parameters' covariance and the residual's level of {} ({}); tau_band_* in the CSV is its "
        "half-width\n",
        options.uncertainty.empty() ? (fs::path(options.params).parent_path() / "uncertainty.yaml").string()
                                    : options.uncertainty,
        u->source);
  fmt::print("raw: RMSE against the {}\n", raw_filter);
  fmt::print("predicted torque: {}\n", one ? out.string() : (out / "*.predicted.csv").string());
}

}  // namespace

void add_predict_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<PredictOptions>();
  auto* cmd = app.add_subcommand("predict",
                                 "A model's inverse-dynamics torque on a log's measured motion (or every run of "
                                 "a dataset), beside the measured torque, with the RMSE per joint");
  add_robot_options(cmd, common);
  cmd->add_option("--params", o->params,
                  "A study's report/parameters.yaml, or `nominal` (robot.yaml's nominal "
                  "standard parameters, e.g. a URDF's)")
      ->capture_default_str();
  cmd->add_option("--model", o->model,
                  "Model: a robot.yaml variant or full (default: the parameters file's, or "
                  "robot.yaml's identified)");
  cmd->add_option("input", o->input, "A log (CSV with its .meta.yaml) or a dataset folder")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->add_option("-o,--out", o->out, "The CSV to write (a folder of <run>.predicted.csv for a dataset)")->required();
  numbers::add_log_options(cmd, o->interval_ms, o->torque_delay_ms, o->trial);
  cmd->add_option("--band", o->band,
                  "Level of the prediction band (tau_band_* columns, and the share of samples inside), from the "
                  "study's report/uncertainty.yaml beside --params; 0: none")
      ->check(numbers::checked(0, 0.999, false, false, "from 0 (none) to 0.999"))
      ->capture_default_str();
  cmd->add_option("--uncertainty", o->uncertainty,
                  "The parameters' uncertainty for the band (default: uncertainty.yaml beside --params)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--force", o->force, "Overwrite existing output files");
  cmd->callback([&common, o, cmd] {
    o->torque_delay_given = cmd->count("--torque-delay") > 0;
    run(common, *o);
  });
}

}  // namespace symoro::dynid
