// dynid observer: the generalized-momentum observer of a model (symoro/observer/) over logs: its
// residual r(t) per joint (the external torque through a first-order lag), thresholds per joint
// from residuals without contact at a stated false-alarm rate, and the events where r leaves
// them (collisions). The logs' measured q, qd and tau as logged: no filter, no acceleration.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "dynid_common.hpp"
#include "dynid_numbers.hpp"
#include "dynid_robots.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/observer/collision_detection.hpp"
#include "symoro/observer/momentum_observer.hpp"

namespace symoro::dynid {

namespace {

namespace fs = std::filesystem;

struct ObserverCliOptions {
  std::string params = "nominal", model, input, out, thresholds;
  std::vector<std::string> calibrate;
  std::string gain_text;  // --gain: one K, or one per joint, comma-separated
  double false_alarms_per_hour = observer::ThresholdOptions{}.false_alarms_per_hour;
  double peak_margin = observer::ThresholdOptions{}.peak_margin;
  double merge_within = observer::kMergeWithin;
  bool derivatives = false, force = false;
};

struct NamedLog {
  std::string name;
  io::Log log;
};

// A log file alone, or a dataset's runs (`held_out`: only those of the held-out family).
std::vector<NamedLog> read_logs(const Common& common, const std::string& path, int joints, bool held_out) {
  std::vector<NamedLog> out;
  if (fs::is_directory(path)) {
    const io::Dataset data = io::read_dataset(path);
    io::check_dataset_robot(data, common.robot);
    for (const auto& r : data.runs)
      if (!held_out || r.family == io::kHeldOutFamily)
        out.push_back({fmt::format("{}_{}", r.trajectory, r.trial), io::read_run_log(r, common.robot, joints)});
    if (out.empty()) throw UsageError(fmt::format("{}: no {}run", path, held_out ? "held-out (family V) " : ""));
  } else {
    io::Log log = io::read_log(path);
    io::check_log_robot(log, path, common.robot, joints);
    out.push_back({fs::path(path).stem().string(), std::move(log)});
  }
  return out;
}

// The gains as printed: one number when they are all equal, else one per joint.
std::string gain_text(const Eigen::VectorXd& gain) {
  if (gain.minCoeff() == gain.maxCoeff()) return io::number_text(gain(0));
  std::string s;
  for (Eigen::Index j = 0; j < gain.size(); ++j) s += (j ? ", " : "") + io::number_text(gain(j));
  return "(" + s + ")";
}

// --gain's values: each a number above 0 and at most 1e5 1/s.
std::vector<double> gains(const std::string& text) {
  std::vector<double> out;
  if (text.empty()) return out;
  std::size_t from = 0;
  while (from <= text.size()) {
    const std::size_t comma = std::min(text.find(',', from), text.size());
    const std::string item = text.substr(from, comma - from);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(v > 0) || !(v <= 1e5))
      throw UsageError(fmt::format("--gain: '{}' is not a gain (a number above 0 and at most 1e5, 1/s)", item));
    out.push_back(v);
    from = comma + 1;
  }
  return out;
}

std::string residual_csv(const io::Log& log, const Eigen::MatrixXd& r, const std::vector<JointInfo>& joints) {
  std::string text = "time";
  for (const auto& j : joints) text += std::string(",r_") + j.name;
  text += "\n";
  for (Eigen::Index k = 0; k < r.rows(); ++k) {
    text += io::number_text(log.time(k));
    for (Eigen::Index j = 0; j < r.cols(); ++j) text += "," + io::number_text(r(k, j));
    text += "\n";
  }
  return text;
}

// The thresholds: read from --thresholds, else calibrated on --calibrate (logs, or datasets'
// held-out runs), else on the input dataset's held-out runs.
observer::ObserverThresholds thresholds_of(const Common& common, const ObserverCliOptions& options,
                                           observer::MomentumObserver& obs, const robot::ModelHandle& model,
                                           std::string& text) {
  std::vector<std::string> names;
  for (const auto& j : model.joints()) names.push_back(j.name);
  if (!options.thresholds.empty()) {
    const observer::ThresholdsFile f = observer::read_thresholds_yaml(options.thresholds, names);
    if (!f.gain.isApprox(obs.gain()))
      throw UsageError(fmt::format("{}: its thresholds were made with other gains than this observer's (--gain)",
                                   options.thresholds));
    return f.thresholds;
  }
  std::vector<std::string> sources = options.calibrate;
  if (sources.empty()) {
    if (!fs::is_directory(options.input))
      throw UsageError(
          "no thresholds: give --thresholds (a thresholds.yaml dynid observer wrote) or --calibrate (logs without "
          "contact, or a dataset whose held-out runs have none)");
    sources.push_back(options.input);
  }
  std::vector<Eigen::MatrixXd> residuals;
  std::vector<Eigen::VectorXd> times;
  std::string on;
  for (const auto& s : sources)
    for (const auto& [name, log] : read_logs(common, s, model.nq(), true)) {
      residuals.push_back(observer::observe_log(obs, log));
      times.push_back(log.time);
      on += (on.empty() ? "" : ", ") + (fs::is_directory(s) ? s + ":" + name : s);
    }
  observer::ThresholdOptions to;
  to.false_alarms_per_hour = options.false_alarms_per_hour;
  to.peak_margin = options.peak_margin;
  const observer::ObserverThresholds t = observer::observer_thresholds(residuals, times, obs.gain(), to);
  text = observer::thresholds_yaml(t, names, common.robot, model.label(), obs.gain(), on);
  return t;
}

void run(const Common& common, const ObserverCliOptions& options) {
  const robot::ModelHandle model = robot_model(common, parameters_model(options.params, options.model));
  const Eigen::VectorXd phi = parameters_phi(common, model, options.params);
  const int n = model.nq();
  observer::MomentumObserverOptions mo;
  const std::vector<double> gain = gains(options.gain_text);
  if (gain.size() == 1) mo.default_gain = gain[0];
  if (gain.size() > 1) {
    if (static_cast<int>(gain.size()) != n)
      throw UsageError(fmt::format("--gain: {} values for {} joints (one, or one per joint)", gain.size(), n));
    mo.gain = Eigen::Map<const Eigen::VectorXd>(gain.data(), n);
  }
  if (options.derivatives) mo.inertia_rate = observer::InertiaRate::derivatives;
  observer::MomentumObserver obs(model, phi, mo);

  const fs::path out(options.out);
  const fs::path events_file = out / "events.csv", thresholds_file = out / "thresholds.yaml";
  const std::vector<NamedLog> logs = read_logs(common, options.input, n, false);
  std::vector<fs::path> files{events_file};
  if (options.thresholds.empty()) files.push_back(thresholds_file);  // calibrated here: written
  for (const auto& l : logs) files.push_back(out / (l.name + ".residual.csv"));
  for (const auto& f : files)
    if (fs::exists(f) && !options.force)
      throw UsageError(f.string() + " exists: dynid observer does not overwrite it; choose another -o, or --force");

  std::string thresholds_text;
  const observer::ObserverThresholds t = thresholds_of(common, options, obs, model, thresholds_text);
  fs::create_directories(out);
  if (!thresholds_text.empty()) io::write_file_atomically(thresholds_file, thresholds_text);

  fmt::print(
      "{} model {} with {} parameters: momentum observer, gain {} 1/s; band per joint |r - center| <= "
      "threshold ({}):\n",
      common.robot, model.label(), options.params == "nominal" ? "the nominal" : options.params, gain_text(obs.gain()),
      thresholds_text.empty()
          ? options.thresholds
          : fmt::format("{} false alarms per hour, {} windows of {:.3g} s, peak margin {:.3g}",
                        io::number_text(t.false_alarms_per_hour), t.windows, t.window, t.peak_margin));
  for (int j = 0; j < n; ++j)
    fmt::print("  {:<16} center {:+.4f}  threshold {:.4f}\n", model.joints()[j].name, t.center(j), t.threshold(j));
  if (!thresholds_text.empty())
    fmt::print("  calibrated on {} samples ({:.1f} s); the tail band alone would alarm {} times there\n", t.samples,
               t.seconds, t.tail_alarms);

  std::string events = "run,joint,start,end,peak,peak_time\n";
  int count = 0;
  for (const auto& [name, log] : logs) {
    const Eigen::MatrixXd r = observer::observe_log(obs, log);
    io::write_file_atomically(out / (name + ".residual.csv"), residual_csv(log, r, model.joints()));
    const auto found = observer::collision_events(log.time, r, t, options.merge_within);
    fmt::print("  {:<12} {:>7} samples: {} event{}\n", name, log.samples(), found.size(), found.size() == 1 ? "" : "s");
    for (const auto& e : found) {
      events += fmt::format("{},{},{},{},{},{}\n", name, model.joints()[e.joint].name, io::number_text(e.start),
                            io::number_text(e.end), io::number_text(e.peak), io::number_text(e.peak_time));
      if (++count <= 20)
        fmt::print("    t = {:.3f} s  {}  peak {:+.4g} at {:.3f} s, until {:.3f} s\n", e.start,
                   model.joints()[e.joint].name, e.peak, e.peak_time, e.end);
    }
  }
  if (count > 20) fmt::print("  ... {} events in all\n", count);
  io::write_file_atomically(events_file, events);
  fmt::print("residuals: {}; events: {}{}\n", (out / "*.residual.csv").string(), events_file.string(),
             thresholds_text.empty() ? "" : "; thresholds: " + thresholds_file.string());
}

}  // namespace

void add_observer_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ObserverCliOptions>();
  auto* cmd = app.add_subcommand("observer",
                                 "Collision detection from a model: the momentum observer's residual r(t) per "
                                 "joint over a log or a dataset's runs, thresholds at a false-alarm rate, and events");
  add_robot_options(cmd, common);
  cmd->add_option("--params", o->params,
                  "A study's report/parameters.yaml, or `nominal` (robot.yaml's nominal standard parameters)")
      ->capture_default_str();
  cmd->add_option("--model", o->model, "Model: a robot.yaml variant or full (default: the parameters file's)");
  cmd->add_option("input", o->input, "A log (CSV with its .meta.yaml) or a dataset folder")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->add_option("-o,--out", o->out, "Folder for <run>.residual.csv, events.csv and thresholds.yaml")->required();
  cmd->add_option("--gain", o->gain_text,
                  "The observer's gain K, 1/s: one for every joint, or one per joint, comma-separated (default 50)");
  cmd->add_option("--calibrate", o->calibrate,
                  "Logs without contact, or datasets (their held-out runs), for the thresholds (default: the input "
                  "dataset's held-out runs)")
      ->check(CLI::ExistingPath);
  auto* th = cmd->add_option("--thresholds", o->thresholds, "A thresholds.yaml dynid observer wrote (no calibration)")
                 ->check(CLI::ExistingFile);
  cmd->add_option("--false-alarms", o->false_alarms_per_hour,
                  "False alarms per hour of motion the thresholds allow (all joints together)")
      ->check(numbers::checked(0, 1e6, true, false, "above 0"))
      ->capture_default_str();
  cmd->add_option("--peak-margin", o->peak_margin, "Thresholds at least this times the calibration's largest excursion")
      ->check(numbers::checked(1, 100, false, false, "from 1 to 100"))
      ->capture_default_str();
  cmd->get_option("--calibrate")->excludes(th);
  cmd->add_option("--merge-within", o->merge_within,
                  "s: a joint's span outside its band this soon after its last continues that event")
      ->check(numbers::checked(0, 3600, false, false, "from 0 to 3600 s"))
      ->capture_default_str();
  cmd->add_flag("--derivatives", o->derivatives,
                "Mdot qd from the model's inertia derivatives (default: differences of M, as accurate and cheaper)");
  cmd->add_flag("--force", o->force, "Overwrite existing output files");
  cmd->callback([&common, o] { run(common, *o); });
}

}  // namespace symoro::dynid
