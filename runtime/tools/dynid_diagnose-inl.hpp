// dynid diagnose's body for one model (included by the generated units only): the stepwise
// selection of missing effects, the backlash stage on the twin, the report and the variant.
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "dynid_diagnose.hpp"
#include "symoro/control/description.hpp"
#include "symoro/diagnose/diagnosis.hpp"
#include "symoro/diagnose/stack_builder.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/identify/raw_torque.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/log.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::dynid {

namespace diagnose_detail {

// The fitting and held-out runs: as named, else the dataset's (held out: family V, as a split
// at import records it; fitting: every other run of the trial).
inline std::pair<std::vector<std::string>, std::vector<std::string>> run_names(const io::Dataset& data, const DiagnoseOptions& o) {
  auto pick = [&](bool heldout) {
    std::vector<std::string> v;
    for (const auto& r : data.runs)
      if (r.trial == o.trial && (r.family == "V") == heldout && std::find(v.begin(), v.end(), r.trajectory) == v.end())
        v.push_back(r.trajectory);
    return v;
  };
  std::vector<std::string> train = o.train.empty() ? pick(false) : o.train, heldout = o.heldout.empty() ? pick(true) : o.heldout;
  std::string all;
  for (const auto& r : data.runs) all += fmt::format("{}{} (family {}, trial {})", all.empty() ? "" : ", ", r.trajectory, r.family, r.trial);
  const auto manifest = (data.dir / "dataset.yaml").string();
  if (train.empty())
    throw UsageError(fmt::format("{}: no fitting run for trial {} (runs: {}); name them with --train", manifest, o.trial, all));
  if (heldout.empty())
    throw UsageError(fmt::format("{}: no held-out run (family V) for trial {} (runs: {}); name them with --heldout, or split "
                                 "a long run at import (dynid import --split 0.7)", manifest, o.trial, all));
  for (const auto* list : {&train, &heldout})
    for (const auto& name : *list) {
      bool found = false;
      for (const auto& r : data.runs) found = found || (r.trajectory == name && r.trial == o.trial);
      if (!found)
        throw UsageError(fmt::format("{}: no run {} of trial {} to {} (runs: {}); choose others with --train / --heldout",
                                     manifest, name, o.trial, list == &train ? "fit" : "hold out", all));
    }
  return {train, heldout};
}

}  // namespace diagnose_detail

template <class Full, class Model>
void DiagnoseCommand::run(const Common& common, const DiagnoseOptions& o) {
  const io::Dataset data = io::read_dataset(o.data);
  io::check_dataset_robot(data, Model::robot_name);
  const auto [train_names, heldout_names] = diagnose_detail::run_names(data, o);
  diagnose::StackOptions so;
  so.interval = o.interval_ms / 1000;
  so.cutoff = o.cutoff;
  so.candidates.only = o.only;
  io::Log first_train;  // the backlash stage's run
  std::vector<std::pair<std::string, io::Log>> heldout_logs;  // for the raw-torque gap
  auto stack = [&](const std::vector<std::string>& names, bool fitting) {
    std::vector<diagnose::NamedSamples> runs;
    for (const auto& name : names) {
      io::Log log = io::read_run_log(data.find(name, o.trial), Model::robot_name, Model::nq);
      if (fitting && name == names.front()) first_train = log;
      if (!fitting) heldout_logs.emplace_back(name, log);
      runs.push_back({name, preprocess::preprocess(log, log.meta.sample_time > 0 ? log.meta.sample_time : 0.001,
                                                   diagnose::light_preprocessing())});
    }
    return diagnose::stack_design<Full, Model>(runs, so);
  };
  // The gap of an earlier identification as it stands: its parameters are held, not refitted
  // (read first: a bad file is named before the logs are worked through).
  Eigen::VectorXd held;
  if (!o.params.empty()) {
    std::vector<std::string> names;
    for (const auto& p : Model::parameters) names.emplace_back(p.name);
    held = io::read_parameters_yaml(o.params, names);
  }
  diagnose::DesignStack train = stack(train_names, true), heldout = stack(heldout_names, false);
  if (held.size()) {
    train.hold(held);
    heldout.hold(held);
  }
  diagnose::DiagnosisOptions dopt;
  dopt.selection.alpha = o.alpha;
  dopt.selection.min_heldout_gain = o.min_gain;
  dopt.selection.min_effect_torque = o.min_torque;
  dopt.selection.candidates = so.candidates;
  // A delay the controller description already models is not a missing effect.
  const auto controller_path = common.robot_dir() / control::controller_file_name();
  if (std::filesystem::exists(controller_path))
    dopt.selection.modeled_delay = control::read_controller_description(controller_path, Full::nq).communication_delay;
  diagnose::Diagnosis d = diagnose::diagnose(train, heldout, dopt);
  // The held-out gap against the raw torque at the logs' own rate: the same fits (on the
  // diagnosis grid), evaluated on the raw-torque samples with a stack whose low-pass is above
  // the band (0.4 of the rate).
  try {
    const identify::RawTorqueOptions ro;
    std::vector<diagnose::NamedSamples> raw_runs;
    for (const auto& [name, log] : heldout_logs) raw_runs.push_back({name, identify::raw_torque_samples(log, ro)});
    diagnose::StackOptions rs = so;
    rs.interval = raw_runs.front().samples.interval;
    rs.cutoff = 0.4 / rs.interval;
    diagnose::DesignStack raw = diagnose::stack_design<Full, Model>(raw_runs, rs);
    if (held.size()) raw.hold(held);
    std::vector<diagnose::Candidate> effects;
    for (const auto& e : d.selection.effects) effects.push_back(e.candidate);
    const diagnose::Fit b = diagnose::fit_with_effects(train, raw, {}, d.selection.weights);
    const diagnose::Fit a = diagnose::fit_with_effects(train, raw, effects, d.selection.weights);
    d.raw_before = b.heldout_rmse;
    d.raw_after = a.heldout_rmse;
    d.raw_total_before = b.heldout_total;
    d.raw_total_after = a.heldout_total;
    d.raw_filter = identify::raw_torque_filter_text(ro);
    fmt::print("held-out rms residual against the raw torque: {:.4f} -> {:.4f} N m\n", d.raw_total_before, d.raw_total_after);
  } catch (const std::exception& e) {
    d.raw_note = e.what();
  }
  // Backlash from the closed loop's high band: the robot's digital twin replays the fitting
  // run's own references. A stage that cannot run, or fails, is said in the report; what the
  // selection found stands either way.
  const auto twin_path = common.robot_dir() / "twin.yaml";
  if (o.no_backlash) {
    d.backlash_note = "Not run (--no-backlash).";
  } else if (!std::filesystem::exists(twin_path)) {
    d.backlash_note = fmt::format("Not run: the stage simulates the robot's digital twin, and {} has none ({} not found).",
                                  common.robot, twin_path.string());
  } else if (!first_train.has_references()) {
    d.backlash_note = fmt::format("Not run: the log of {} has no reference columns (q_ref, qd_ref, qdd_ref) for the twin to "
                                  "replay.", train_names.front());
  } else {
    try {
      const twin::TwinConfig nominal =
          diagnose::with_selected_effects(twin::read_twin_config(twin_path, Full::nq), d.selection);
      const auto reference = trajectory::sampled_reference(first_train, nominal.controller.period);
      d.backlash = diagnose::fit_backlash<Full>(first_train, reference, nominal);
      d.backlash_judged = true;
    } catch (const std::exception& e) {
      d.backlash_note = fmt::format("Failed after the selection, so no play is named: {}", e.what());
    }
  }
  if (!d.backlash_note.empty()) fmt::print("backlash stage: {}\n", d.backlash_note);
  d.robot = common.robot;
  d.model = std::string(Model::robot_name) + (std::string(Model::variant_name).empty() ? "" : "::" + std::string(Model::variant_name));
  d.cutoff = o.cutoff;
  d.held_parameters = o.params;
  for (const auto& e : d.selection.dropped)
    fmt::print("dropped: {}: {} ({})\n", e.candidate.label(), e.magnitude, e.reason);
  for (const auto& e : d.selection.effects)
    fmt::print("effect: {}: {} (F {:.1f}, held-out gain {:.1f} %)\n", e.candidate.label(), e.magnitude.text, e.f,
               100 * e.heldout_gain);
  for (const auto& f : d.backlash.findings)
    fmt::print("effect: backlash, joint {}: {:.3f} deg of play (high-band torque {:.3f} N m measured, {:.3f} simulated "
               "without it, {:.3f} with it)\n",
               f.joint, f.width * 180 / 3.14159265358979323846, f.measured, f.simulated_before, f.simulated_after);
  if (d.backlash.delay > 0) fmt::print("actuation delay refined on the high band: {:.2f} ms\n", d.backlash.delay * 1e3);
  if (d.selection.effects.empty() && d.backlash.findings.empty())
    fmt::print("no missing effect found ({})\n", d.selection.stop_reason);
  fmt::print("held-out rms residual: {:.4f} -> {:.4f} N m\n", d.selection.before.heldout_total, d.selection.after.heldout_total);
  const std::filesystem::path out(o.out);
  const auto files = diagnose::write_diagnosis_report(d, out);
  const std::string base = std::string(Model::variant_name).empty() ? std::string() : std::string(Model::variant_name);
  const std::string name = o.variant.empty() ? (base.empty() ? "diagnosed" : base + "_diagnosed") : o.variant;
  const std::string variant = diagnose::variant_yaml(d, name, base.empty() ? "full" : base);
  if (!variant.empty()) {
    io::write_file_atomically(out / "variant.yaml", "# Add under `variants:` of robots/" + common.robot + "/robot.yaml\n" + variant);
    fmt::print("variant: {}\n", (out / "variant.yaml").string());
  }
  fmt::print("report: {} ({} files)\n", (out / "diagnosis.md").string(), files.size());
  if (!o.apply.empty()) {
    if (variant.empty()) throw UsageError("--apply: nothing to add (no effect found)");
    // robot.yaml gains the variant at its end, which must be the `variants:` section; the file
    // is replaced atomically, so an interrupted run leaves the old one.
    const auto yaml = common.robot_dir() / "robot.yaml";
    std::ifstream in(yaml);
    std::stringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    const auto at = s.rfind("\nvariants:");
    if (at == std::string::npos) throw UsageError(yaml.string() + ": no top-level `variants:` section to add to");
    for (auto p = s.find('\n', at + 1); p != std::string::npos && p + 1 < s.size(); p = s.find('\n', p + 1))
      if (s[p + 1] != ' ' && s[p + 1] != '#' && s[p + 1] != '\n')
        throw UsageError(yaml.string() + ": `variants:` must be the last section to add to it");
    if (s.find("\n  " + name + ":") != std::string::npos) throw UsageError(yaml.string() + ": variant '" + name + "' exists");
    if (!s.empty() && s.back() != '\n') s += '\n';
    io::write_file_atomically(yaml, s + variant);
    fmt::print("added variant '{}' to {}; regenerate (symoroc generate {} -o generated) and rebuild, then "
               "dynid identify --model {}\n", name, yaml.string(), common.robot_dir().string(), name);
  }
}

}  // namespace symoro::dynid
