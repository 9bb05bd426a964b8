// The diagnosis of a dataset (dataset_diagnosis.hpp), for any model through its DiagnosisModel.
#include "symoro/diagnose/dataset_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <regex>
#include <utility>

#include <fmt/format.h>

#include "symoro/control/description.hpp"
#include "symoro/diagnose/effects.hpp"
#include "symoro/study/raw_torque.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/io/text_file.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::diagnose {

void check_request(const DatasetDiagnosisOptions& options) {
  // The ranges dynid diagnose's options check, for every caller (Python passed alpha=nan).
  const auto range = [](const char* option, double v, double lo, double hi, bool lo_open, const char* what) {
    if (!(std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi))
      throw DiagnosisRequestError(fmt::format("{} {}: must be {}", option, v, what));
  };
  if (options.trial < 1 || options.trial > 1'000'000)
    throw DiagnosisRequestError(fmt::format("--trial {}: must be from 1 to 1000000", options.trial));
  range("--interval", options.interval * 1000, 1, 10000, false, "from 1 to 10000 ms");
  range("--cutoff", options.cutoff, 0, 1e5, true, "> 0 and <= 1e5 Hz");
  range("--alpha", options.alpha, 0, 0.5, true, "> 0 and <= 0.5");
  range("--min-gain", options.min_heldout_gain, 0, 1, false, ">= 0 and <= 1");
  range("--min-torque", options.min_effect_torque, 0, 1e6, false, ">= 0 and <= 1e6 N m");
  static const std::regex lower_id("^[a-z][a-z0-9_]*$");
  if (!options.variant.empty() &&
      (!std::regex_match(options.variant, lower_id) || options.variant == "full" || options.variant == "param"))
    throw DiagnosisRequestError("--variant '" + options.variant +
                                "' must be a lower-case identifier other than 'full' and 'param' "
                                "(symoroc's rule)");
  for (const auto& e : options.only) {
    effect_kind(e);  // unknown names: a clear error first
    if (e == "payload" && options.params.empty())
      throw DiagnosisRequestError(
          "--only payload needs --params: a refit absorbs a payload into the last link's parameters, "
          "so it is judged against an earlier identification held fixed");
  }
}

std::pair<std::vector<std::string>, std::vector<std::string>> diagnosis_runs(const io::Dataset& data,
                                                                             const DatasetDiagnosisOptions& options) {
  // Held out: the held-out family (V, as a split at import records it); fitting: every other run
  // of the trial.
  auto pick = [&](bool heldout) {
    std::vector<std::string> v;
    for (const auto& r : data.runs)
      if (r.trial == options.trial && (r.family == options.heldout_family) == heldout &&
          std::find(v.begin(), v.end(), r.trajectory) == v.end())
        v.push_back(r.trajectory);
    return v;
  };
  std::vector<std::string> train = options.train.empty() ? pick(false) : options.train,
                           heldout = options.heldout.empty() ? pick(true) : options.heldout;
  std::string all;
  for (const auto& r : data.runs)
    all += fmt::format("{}{} (family {}, trial {})", all.empty() ? "" : ", ", r.trajectory, r.family, r.trial);
  const auto manifest = (data.dir / "dataset.yaml").string();
  if (train.empty())
    throw DiagnosisRequestError(fmt::format("{}: no fitting run for trial {} (runs: {}); name them with --train",
                                            manifest, options.trial, all));
  if (heldout.empty())
    throw DiagnosisRequestError(
        fmt::format("{}: no held-out run (family {}) for trial {} (runs: {}); name them with --heldout, "
                    "or split a long run at import (dynid import --split 0.7)",
                    manifest, options.heldout_family, options.trial, all));
  for (const auto* list : {&train, &heldout})
    for (const auto& name : *list) {
      bool found = false;
      for (const auto& r : data.runs) found = found || (r.trajectory == name && r.trial == options.trial);
      if (!found)
        throw DiagnosisRequestError(
            fmt::format("{}: no run {} of trial {} to {} (runs: {}); choose others with --train / --heldout", manifest,
                        name, options.trial, list == &train ? "fit" : "hold out", all));
    }
  return {train, heldout};
}

namespace {

// The held-out gap against the raw torque at the logs' own rate: the same fits (on the
// diagnosis grid), evaluated on the raw-torque samples with a stack whose low-pass is above the
// band (0.4 of the rate).
void score_raw_torque(const DiagnosisModel& model, const DesignStack& train,
                      const std::vector<std::pair<std::string, io::Log>>& heldout_logs, const StackOptions& so,
                      const Eigen::VectorXd& held, Diagnosis& d) {
  const study::RawTorqueOptions ro;
  std::vector<NamedSamples> raw_runs;
  for (const auto& [name, log] : heldout_logs) raw_runs.push_back({name, study::raw_torque_samples(log, ro)});
  StackOptions rs = so;
  rs.interval = raw_runs.front().samples.interval;
  rs.cutoff = 0.4 / rs.interval;
  DesignStack raw = model.stack_design(raw_runs, rs);
  if (held.size()) raw.hold(held);
  std::vector<Candidate> effects;
  for (const auto& e : d.selection.effects) effects.push_back(e.candidate);
  const Fit b = fit_with_effects(train, raw, {}, d.selection.weights, d.options.max_lag);
  const Fit a = fit_with_effects(train, raw, effects, d.selection.weights, d.options.max_lag);
  d.raw_before = b.heldout_rmse;
  d.raw_after = a.heldout_rmse;
  d.raw_total_before = b.heldout_total;
  d.raw_total_after = a.heldout_total;
  d.raw_filter = study::raw_torque_filter_text(ro);
}

}  // namespace

namespace {

// Backlash from the closed loop's high band: the robot's digital twin replays the fitting run's
// own references. A stage that cannot run, or fails, is said in the report (d.backlash_note).
void backlash_stage(const DiagnosisModel& model, const DatasetDiagnosisOptions& options, const std::string& robot,
                    const io::Log& first_train, const std::string& first_train_name,
                    const std::function<void()>& check_stop, Diagnosis& d) {
  const identify::ModelDescription& md = model.description();
  const auto twin_path = options.robot_dir / "twin.yaml";
  if (!options.backlash) {
    d.backlash_note = "Not run (--no-backlash).";
  } else if (options.robot_dir.empty()) {
    d.backlash_note = "Not run: the stage simulates the robot's digital twin, and no robot folder was given.";
  } else if (!std::filesystem::exists(twin_path)) {
    d.backlash_note =
        fmt::format("Not run: the stage simulates the robot's digital twin, and {} has none ({} not found).", robot,
                    twin_path.string());
  } else if (!first_train.has_references()) {
    d.backlash_note = fmt::format(
        "Not run: the log of {} has no reference columns (q_ref, qd_ref, qdd_ref) for the twin to "
        "replay.",
        first_train_name);
  } else {
    check_stop();
    try {
      const twin::TwinConfig nominal = with_selected_effects(twin::read_twin_config(twin_path, md.nq), d.selection);
      const auto reference = trajectory::sampled_reference(first_train, nominal.controller.period);
      d.backlash = model.fit_backlash(first_train, reference, nominal, BacklashFitOptions{});
      d.backlash_judged = true;
    } catch (const std::exception& e) {
      d.backlash_note = fmt::format("Failed after the selection, so no play is named: {}", e.what());
    }
  }
}

// What the diagnosis named (and dropped), said line by line.
void say_findings(const Diagnosis& d, const std::function<void(const std::string&)>& say) {
  for (const auto& e : d.selection.dropped)
    say(fmt::format("dropped: {}: {} ({})", e.candidate.label(), e.magnitude, e.reason));
  for (const auto& e : d.selection.effects)
    say(fmt::format("effect: {}: {} (F {:.1f}, held-out gain {:.1f} %)", e.candidate.label(), e.magnitude.text, e.f,
                    100 * e.heldout_gain));
  for (const auto& f : d.backlash.findings)
    say(fmt::format(
        "effect: backlash, joint {}: {:.3f} deg of play (high-band torque {:.3f} N m measured, {:.3f} simulated "
        "without it, {:.3f} with it)",
        f.joint, f.width * 180 / 3.14159265358979323846, f.measured, f.simulated_before, f.simulated_after));
  if (d.backlash.delay > 0)
    say(fmt::format("actuation delay refined on the high band: {:.2f} ms", d.backlash.delay * 1e3));
  if (d.selection.effects.empty() && d.backlash.findings.empty())
    say(fmt::format("no missing effect found ({})", d.selection.stop_reason));
}

}  // namespace

DatasetDiagnosis diagnose_dataset(const DiagnosisModel& model, const DatasetDiagnosisOptions& options) {
  check_request(options);
  const identify::ModelDescription& md = model.description();
  auto say = [&](const std::string& line) {
    if (options.say) options.say(line);
  };
  auto check_stop = [&] {
    if (options.stop && options.stop()) throw DiagnosisStopped();
  };
  const io::Dataset data = io::read_dataset(options.data);
  io::check_dataset_robot(data, md.robot);
  const auto [train_names, heldout_names] = diagnosis_runs(data, options);
  StackOptions so;
  so.interval = options.interval;
  so.cutoff = options.cutoff;
  so.candidates.only = options.only;
  io::Log first_train;                                        // the backlash stage's run
  std::vector<std::pair<std::string, io::Log>> heldout_logs;  // for the raw-torque gap
  auto stack = [&](const std::vector<std::string>& names, bool fitting) {
    std::vector<NamedSamples> runs;
    for (const auto& name : names) {
      check_stop();
      io::Log log = io::read_run_log(data.find(name, options.trial), md.robot, md.nq);
      if (fitting && name == names.front()) first_train = log;
      if (!fitting) heldout_logs.emplace_back(name, log);
      runs.push_back({name, preprocess::preprocess(log, log.meta.sample_time > 0 ? log.meta.sample_time : 0.001,
                                                   light_preprocessing())});
    }
    return model.stack_design(runs, so);
  };
  // The gap of an earlier identification as it stands: its parameters are held, not refitted
  // (read first: a bad file is named before the logs are worked through).
  Eigen::VectorXd held;
  if (!options.params.empty()) {
    std::vector<std::string> names;
    for (const auto& p : md.parameters) names.emplace_back(p.name);
    held = io::read_parameters_yaml(options.params.string(), names);
  }
  DesignStack train = stack(train_names, true), heldout = stack(heldout_names, false);
  if (held.size()) {
    train.hold(held);
    heldout.hold(held);
  }
  DiagnosisOptions dopt;
  dopt.selection.alpha = options.alpha;
  dopt.selection.min_heldout_gain = options.min_heldout_gain;
  dopt.selection.min_effect_torque = options.min_effect_torque;
  dopt.selection.candidates = so.candidates;
  // A delay the controller description already models is not a missing effect.
  const auto controller_path = options.robot_dir / control::controller_file_name();
  if (!options.robot_dir.empty() && std::filesystem::exists(controller_path))
    dopt.selection.modeled_delay = control::read_controller_description(controller_path, md.nq).communication_delay;
  check_stop();
  DatasetDiagnosis result;
  Diagnosis& d = result.diagnosis;
  d = diagnose(train, heldout, dopt);
  check_stop();
  try {
    score_raw_torque(model, train, heldout_logs, so, held, d);
    say(fmt::format("held-out rms residual against the raw torque: {:.4f} -> {:.4f} N m", d.raw_total_before,
                    d.raw_total_after));
  } catch (const std::exception& e) {
    d.raw_note = e.what();
  }
  // Backlash from the closed loop's high band (a stage that cannot run is said in the report).
  const std::string robot = options.robot_dir.empty() ? md.robot : options.robot_dir.filename().string();
  backlash_stage(model, options, robot, first_train, train_names.front(), check_stop, d);
  if (!d.backlash_note.empty()) say(fmt::format("backlash stage: {}", d.backlash_note));
  d.robot = robot;
  d.model = md.robot + (md.variant.empty() ? "" : "::" + md.variant);
  d.cutoff = options.cutoff;
  d.held_parameters = options.params.string();
  say_findings(d, say);
  say(fmt::format("held-out rms residual: {:.4f} -> {:.4f} N m", d.selection.before.heldout_total,
                  d.selection.after.heldout_total));
  check_stop();  // the last chance: from here the report is written whole
  result.files = write_diagnosis_report(d, options.out);
  result.report = options.out / "diagnosis.md";
  const std::string& base = md.variant;
  result.variant_name = options.variant.empty() ? (base.empty() ? "diagnosed" : base + "_diagnosed") : options.variant;
  result.variant_yaml = variant_yaml(d, result.variant_name, base.empty() ? "full" : base);
  if (!result.variant_yaml.empty()) {
    result.variant_file = options.out / "variant.yaml";
    io::write_file_atomically(result.variant_file,
                              "# Add under `variants:` of robots/" + robot + "/robot.yaml\n" + result.variant_yaml);
    say(fmt::format("variant: {}", result.variant_file.string()));
  }
  say(fmt::format("report: {} ({} files)", result.report.string(), result.files.size()));
  return result;
}

void add_variant_to_robot_yaml(const std::filesystem::path& yaml, const std::string& name, const std::string& variant) {
  if (variant.empty()) throw DiagnosisRequestError("--apply: nothing to add (no effect found)");
  // robot.yaml gains the variant at its end, which must be the `variants:` section, or a new
  // section when it has none (symoroc model writes none); the file is replaced atomically, so an
  // interrupted run leaves the old one.
  std::string s = io::read_text_file(yaml);
  if (!s.empty() && s.back() != '\n') s += '\n';
  const auto found = ("\n" + s).rfind("\nvariants:");  // where its line starts in s
  if (found == std::string::npos) {
    io::write_file_atomically(yaml, s + "variants:\n" + variant);
    return;
  }
  for (auto p = s.find('\n', found); p != std::string::npos && p + 1 < s.size(); p = s.find('\n', p + 1))
    if (s[p + 1] != ' ' && s[p + 1] != '#' && s[p + 1] != '\n')
      throw DiagnosisRequestError(yaml.string() + ": `variants:` must be the last section to add to it");
  if (s.find("\n  " + name + ":") != std::string::npos)
    throw DiagnosisRequestError(yaml.string() + ": variant '" + name + "' exists");
  io::write_file_atomically(yaml, s + variant);
}

}  // namespace symoro::diagnose
