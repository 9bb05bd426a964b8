#include "symoro/diagnose/diagnosis.hpp"

#include <cmath>
#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "symoro/diagnose/localize_report.hpp"
#include "symoro/report/svg_plot.hpp"
#include "symoro/io/atomic_file.hpp"

namespace symoro::diagnose {

std::vector<ResidualSeries> residual_series(const DesignStack& d, const Eigen::VectorXd& tau_model) {
  std::vector<ResidualSeries> out;
  const int n = d.joints, S = d.samples();
  for (int a = 0; a < S;) {
    int b = a + 1;
    while (b < S && d.segment[b] == d.segment[a]) ++b;
    ResidualSeries r;
    r.name = d.segment_trajectory[static_cast<std::size_t>(d.segment[a])];
    r.interval = d.interval;
    r.time = d.time.segment(a, b - a);
    r.q = d.q.middleRows(a, b - a);
    r.qd = d.qd.middleRows(a, b - a);
    r.qdd = d.qdd.middleRows(a, b - a);
    r.tau_measured = d.tau.middleRows(a, b - a);
    r.tau_model.resize(b - a, n);
    for (int s = a; s < b; ++s)
      r.tau_model.row(s - a) = tau_model.segment(static_cast<Eigen::Index>(s) * n, n).transpose();
    out.push_back(std::move(r));
    a = b;
  }
  return out;
}

Diagnosis diagnose(const DesignStack& train, const DesignStack& heldout, const DiagnosisOptions& options) {
  Diagnosis d;
  d.interval = train.interval;
  std::set<std::string> seen;
  for (const auto& t : train.segment_trajectory)
    if (seen.insert("t" + t).second) d.train.push_back(t);
  for (const auto& t : heldout.segment_trajectory)
    if (seen.insert("h" + t).second) d.heldout.push_back(t);
  d.options = options.selection;
  d.selection = select_effects(train, heldout, options.selection);
  d.before_series = residual_series(heldout, d.selection.before.heldout_tau);
  d.after_series = residual_series(heldout, d.selection.after.heldout_tau);
  d.before = localize(d.before_series, heldout.joint_names, options.localize);
  d.after = localize(d.after_series, heldout.joint_names, options.localize);
  return d;
}

namespace {

std::string rmse_figure(const Diagnosis& d, const std::vector<std::string>& joints) {
  svg::Figure f;
  f.title = "Held-out torque residual per joint (rms), before and after the selected effects";
  svg::Panel p;
  p.x_label = "joint";
  p.y_label = "rms residual (N m)";
  for (std::size_t j = 0; j < joints.size(); ++j) p.categories.push_back(std::to_string(j + 1));
  svg::Series b{"model as identified (refitted)", {}, {}, {}}, a{"with the selected effects", {}, {}, {}};
  b.style.colour = "#d62728";
  a.style.colour = "#2ca02c";
  for (Eigen::Index j = 0; j < d.selection.before.heldout_rmse.size(); ++j) {
    b.y.push_back(d.selection.before.heldout_rmse(j));
    a.y.push_back(d.selection.after.heldout_rmse(j));
  }
  p.bars = {b, a};
  f.panels.push_back(p);
  f.panel_width = 640;
  return svg::render(f);
}

std::string flags(const CandidateTest& t) {
  if (t.absorbed) return "absorbed";
  std::string s;
  s += t.significant ? "significant" : "not significant";
  if (!t.physical)
    s += ", non-physical";
  else if (t.heldout_gain < 0)
    s += ", worse held out";
  return s;
}

}  // namespace

namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& x : v) out += (out.empty() ? "" : ", ") + x;
  return out;
}

// The effects selected (with the note on an actuation delay), and those the backward check dropped.
std::string effects_markdown(const Diagnosis& d) {
  const Selection& s = d.selection;
  std::string m;
  m += "## Effects found\n\n";
  if (s.effects.empty()) {
    m += "None: no candidate effect is significant and improves the held-out trajectories (" + s.stop_reason + ").\n\n";
  } else {
    m += "| # | effect | parameters | magnitude | F | p | held-out gain |\n|---|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < s.effects.size(); ++i) {
      const auto& e = s.effects[i];
      m += fmt::format("| {} | {} | {} | {} | {:.1f} | {:.1e} | {:.1f} % |\n", i + 1, e.candidate.label(),
                       joined(e.candidate.parameters), e.magnitude.text, e.f, e.p_value, 100 * e.heldout_gain);
    }
    m += "\nStopped: " + s.stop_reason + ".\n\n";
    for (const auto& e : s.effects)
      if (e.candidate.kind == EffectKind::ActuationDelay && !e.magnitude.values.empty())
        m += fmt::format(
            "The actuation delay is not a model term: identify with the logged torque read {0:.2f} ms later "
            "(`dynid identify --torque-delay {0:.2f}`, preprocess::Options::torque_delay) and add it to the "
            "controller description's communication_delay for the closed loop{1}.\n\n",
            e.magnitude.values[0] * 1e3,
            d.options.modeled_delay >= 0
                ? fmt::format(" (which models {:.2f} ms; the delay named is beyond it)", d.options.modeled_delay * 1e3)
                : std::string());
  }
  if (!s.dropped.empty()) {
    m += "Named by a forward step, then dropped by the backward check (each named effect refitted with all the others "
         "must have a 95 % region that excludes half its size, agree with its physics, and still lower its joints' "
         "held-out residual):\n\n";
    for (const auto& e : s.dropped) m += fmt::format("- {}: {}; {}.\n", e.candidate.label(), e.magnitude, e.reason);
    m += "\n";
  }
  return m;
}

// The backlash stage: the closed loop's high band against the twin's null, joint by joint.
std::string backlash_markdown(const Diagnosis& d) {
  std::string m;
  if (d.backlash_judged) {
    const BacklashFit& b = d.backlash;
    m += "## Backlash: the closed loop's high band\n\n";
    m += fmt::format(
        "The fitting run's torque above 40 Hz against a null: the robot's digital twin running the same references in "
        "closed loop with the effects above (mean and spread over noise seeds), with the log's own floor, which the "
        "twin "
        "does not model: the encoders' noise estimated from the log ({:.2f} counts) in the loop, and the torque the "
        "controller's law does not explain (the logged torque less the description's FF+PD command of {} row(s) "
        "before, "
        "from the logged position and velocity) added. A joint whose excess over the null exceeds 6 spreads and 50 % "
        "gets "
        "the play whose simulation reproduces it, then the others are judged again.",
        b.floor.encoder_noise, b.floor.lag);
    if (b.delay > 0) m += fmt::format(" The selected delay, refined on the high band: {:.2f} ms.", b.delay * 1e3);
    m += "\n\n| joint | measured (N m) | null (N m) | of which the log's floor (N m) | spread (N m) | play "
         "|\n|---|---|---|---|---|---|\n";
    for (Eigen::Index j = 0; j < b.measured.size(); ++j) {
      std::string play;
      for (const auto& f : b.findings)
        if (f.joint == j + 1) play = fmt::format("{:.3f} deg", f.width * 180 / 3.14159265358979323846);
      m += fmt::format(
          "| {} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {} |\n",
          j < static_cast<Eigen::Index>(d.before.joints.size()) ? d.before.joints[j].name : std::to_string(j + 1),
          b.measured(j), b.simulated(j), j < b.floor.rms.size() ? b.floor.rms(j) : 0.0, b.spread(j),
          play.empty() ? "—" : play);
    }
    m += b.findings.empty() ? "\nNo backlash found.\n\n" : "\n";
    for (const auto& note : b.notes) m += "- " + note + "\n";
    if (!b.notes.empty()) m += "\n";
  }
  if (!d.backlash_note.empty()) m += "## Backlash: the closed loop's high band\n\n" + d.backlash_note + "\n\n";
  return m;
}

// The held-out gap before and after, on the stack's grid and against the raw torque.
std::string gap_markdown(const Diagnosis& d) {
  const Selection& s = d.selection;
  std::string m;
  m += "## The gap before and after (held-out trajectories)\n\n";
  m += "| joint | rms before (N m) | rms after (N m) | change |\n|---|---|---|---|\n";
  for (Eigen::Index j = 0; j < s.before.heldout_rmse.size(); ++j) {
    const double b = s.before.heldout_rmse(j), a = s.after.heldout_rmse(j);
    m += fmt::format("| {} {} | {:.4f} | {:.4f} | {:+.1f} % |\n", j + 1,
                     d.before.joints.size() > static_cast<std::size_t>(j) ? d.before.joints[j].name : "", b, a,
                     b > 0 ? 100 * (a / b - 1) : 0.0);
  }
  m += fmt::format("| all | {:.4f} | {:.4f} | {:+.1f} % |\n\n", s.before.heldout_total, s.after.heldout_total,
                   s.before.heldout_total > 0 ? 100 * (s.after.heldout_total / s.before.heldout_total - 1) : 0.0);
  if (!d.raw_filter.empty()) {
    m += "Against the raw measured torque at the logs' own rate (the same fits; " + d.raw_filter + "):\n\n";
    m += "| joint | rms before (N m) | rms after (N m) | change |\n|---|---|---|---|\n";
    for (Eigen::Index j = 0; j < d.raw_before.size(); ++j) {
      const double b = d.raw_before(j), a = d.raw_after(j);
      m += fmt::format("| {} | {:.4f} | {:.4f} | {:+.1f} % |\n", j + 1, b, a, b > 0 ? 100 * (a / b - 1) : 0.0);
    }
    m += fmt::format("| all | {:.4f} | {:.4f} | {:+.1f} % |\n\n", d.raw_total_before, d.raw_total_after,
                     d.raw_total_before > 0 ? 100 * (d.raw_total_after / d.raw_total_before - 1) : 0.0);
  } else if (!d.raw_note.empty()) {
    m += "Against the raw measured torque: not scored (" + d.raw_note + ").\n\n";
  }
  return m;
}

// The stepwise selection: the weights and the rule, then each step's best candidates.
std::string stepwise_markdown(const Diagnosis& d) {
  const Selection& s = d.selection;
  std::string m;
  m += "## Stepwise selection\n\n";
  m += fmt::format(
      "Weights per joint (1/N m): {}. Each step refits the model with each candidate; F is a score test with the "
      "residual's autocorrelation (effective sample size per candidate), the level ({:g} per step) is "
      "Bonferroni-corrected, "
      "and a candidate must also lower the held-out residual of its joints by at least {:.0f} % and matter (at least "
      "{:g} N m "
      "of torque; a delay at least {:g} log periods); the one removing most of the whole held-out residual is taken, "
      "or one "
      "with fewer parameters that removes within {:.0f} % as much.\n\n",
      [&] {
        std::string w;
        for (Eigen::Index j = 0; j < s.weights.size(); ++j) w += fmt::format("{}{:.3g}", j ? ", " : "", s.weights(j));
        return w;
      }(),
      d.options.alpha, 100 * d.options.min_heldout_gain, d.options.min_effect_torque, d.options.min_delay_periods,
      100 * d.options.parsimony);
  for (std::size_t i = 0; i < s.steps.size(); ++i) {
    const auto& st = s.steps[i];
    m += fmt::format("Step {}: autocorrelation time {:.1f} samples, level {:.1e}; {}.\n\n", i + 1,
                     st.autocorrelation_time, st.level,
                     st.chosen.empty() ? "nothing taken" : "took `" + st.chosen + "`");
    m += "| candidate | F | p | held-out gain | effect rms (N m) | verdict |\n|---|---|---|---|---|---|\n";
    for (std::size_t k = 0; k < std::min<std::size_t>(6, st.tests.size()); ++k) {
      const auto& t = st.tests[k];
      m += fmt::format("| {} | {:.1f} | {:.1e} | {:.2f} % | {:.4f} | {} |\n", t.label, t.f, t.p_value,
                       100 * t.heldout_gain, t.effect_rms, flags(t));
    }
    // Candidates the model's own columns already span (e.g. a spring k sin q on a joint whose
    // axis makes it a gravity term): said, not dropped, since the model may hold them already.
    std::string absorbed;
    for (const auto& t : st.tests)
      if (t.absorbed) absorbed += (absorbed.empty() ? "" : ", ") + t.label;
    if (!absorbed.empty())
      m += "\nAbsorbed (its columns lie in the span of the model's own, or are not excited by these data; the model "
           "can already represent it, and it cannot be judged apart): " +
           absorbed + ".\n";
    m += "\n";
  }
  return m;
}

}  // namespace

std::vector<std::filesystem::path> write_diagnosis_report(const Diagnosis& d, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "figures");
  std::vector<std::filesystem::path> written;
  const Selection& s = d.selection;
  std::string m = "# Model-gap diagnosis\n\n";
  m += fmt::format(
      "Robot `{}`, model `{}`. Fitted on {}; judged on the held-out {}. Grid {:g} ms, every column and "
      "the torque through the same {:g} Hz zero-phase low-pass (parallel filtering).\n\n",
      d.robot, d.model, joined(d.train), joined(d.heldout), d.interval * 1000, d.cutoff);
  if (!d.held_parameters.empty())
    m += "The identified parameters are held at `" + d.held_parameters +
         "` (an earlier identification): only the effects are fitted, so what changed since (a payload) shows.\n\n";
  m += effects_markdown(d);
  m += backlash_markdown(d);
  m += gap_markdown(d);
  io::write_file_atomically(dir / "figures" / "heldout_rmse.svg", rmse_figure(d, {}));
  written.push_back(dir / "figures" / "heldout_rmse.svg");
  m += "![held-out rms per joint](figures/heldout_rmse.svg)\n\n";
  m += stepwise_markdown(d);
  const auto before_figs = write_localization_figures(d.before_series, d.before, dir / "figures", "before");
  std::vector<std::string> before_links, after_links;
  for (const auto& f : before_figs) before_links.push_back("figures/" + f), written.push_back(dir / "figures" / f);
  m += localization_markdown(d.before, before_links, "Where the residual is, before", 2);
  if (!s.effects.empty()) {
    const auto after_figs = write_localization_figures(d.after_series, d.after, dir / "figures", "after");
    for (const auto& f : after_figs) after_links.push_back("figures/" + f), written.push_back(dir / "figures" / f);
    m += localization_markdown(d.after, after_links, "Where the residual is, after", 2);
  }
  io::write_file_atomically(dir / "diagnosis.md", m);
  written.push_back(dir / "diagnosis.md");
  return written;
}

namespace {

// The robot.yaml variant effect a selected effect compiles to (the effect table's).
std::string variant_of(const Candidate& c) { return std::string(effect_info(c.kind).row->variant); }

std::string joint_list(std::vector<int> js) {
  std::sort(js.begin(), js.end());
  std::string out;
  for (int j : js) out += (out.empty() ? "" : ", ") + std::to_string(j);
  return out;
}

// The selected effects as a variant's entries, and notes on those no variant effect carries.
struct VariantEntries {
  std::map<std::string, std::vector<int>> joints;
  // Effects written {joints: [...], <parameter>}: joints grouped by (effect, parameter text).
  std::map<std::string, std::map<std::string, std::vector<int>>> shaped;
  // Effects with a velocity scale per joint ({joints: [...], velocity: v or [v1, ...]}): every
  // selected joint keeps the width it was selected with.
  std::map<std::string, std::map<int, double>> scaled;
  std::string notes;

  void add(const SelectedEffect& e) {
    const Candidate& c = e.candidate;
    switch (c.kind) {
      // Coulomb friction smoothed as the diagnosis found the logs' velocity spread: the files'
      // sign(qd) column is biased towards 0 by it at slow motion. The variant's tanh(qd / width)
      // has the slope at rest of the diagnosis's erf (width = spread sqrt(pi / 2)).
      case EffectKind::Coulomb:
        scaled[variant_of(c)][c.joint] = variant_velocity(c);
        break;
      case EffectKind::Offset:
      case EffectKind::ViscousAsymmetry:
      case EffectKind::InertiaProducts:
        joints[variant_of(c)].push_back(c.joint);
        break;
      // The law itself, sign(qd) exp(-(qd / vs)^2): its level is the law's (effects.hpp).
      case EffectKind::Stribeck:
        scaled[variant_of(c)][c.joint] = variant_velocity(c);
        break;
      case EffectKind::PositionHarmonics: {
        std::string orders;
        for (int k : c.orders) orders += (orders.empty() ? "" : ", ") + std::to_string(k);
        shaped[variant_of(c)]["orders: [" + orders + "]"].push_back(c.joint);
        break;
      }
      case EffectKind::ActuationDelay:
        notes += "    # actuation delay " + e.magnitude.text +
                 ": not a model term; identify with the torque shifted by it (dynid identify --torque-delay " +
                 fmt::format("{:.2f}", e.magnitude.values.empty() ? 0.0 : e.magnitude.values[0] * 1e3) + ")\n";
        break;
      case EffectKind::TorqueConstant:
        notes += fmt::format("    # torque-constant error on joint {} ({}): calibrate the servo's torque constant\n",
                             c.joint, e.magnitude.text);
        break;
      case EffectKind::Backlash:
        notes += fmt::format(
            "    # backlash on joint {} ({}): not a rigid-body term; leave out samples at mesh-torque reversals\n",
            c.joint, e.magnitude.text);
        break;
      case EffectKind::Payload:
        notes += fmt::format(
            "    # payload on link {} ({}): not a new term; identify again with it mounted (dynid identify)\n", c.joint,
            e.magnitude.text);
        break;
      default:  // a row added to the effect table: its variant effect, with the velocity it was found at
        if (variant_of(c).empty())
          notes += fmt::format("    # {} ({}): no variant effect carries it\n", c.label(), e.magnitude.text);
        else if (variant_velocity(c) > 0)
          scaled[variant_of(c)][c.joint] = variant_velocity(c);
        else
          joints[variant_of(c)].push_back(c.joint);
        break;
    }
  }

  // The `effects:` lines; a shaped effect's other groups go into the notes.
  std::string effects() {
    std::string effects;
    for (auto& [key, js] : joints) effects += "      " + key + ": [" + joint_list(js) + "]\n";
    for (const auto& [key, widths] : scaled) {
      std::vector<int> js;
      std::string values;
      bool same = true;
      for (const auto& [j, v] : widths) {
        js.push_back(j);
        values += fmt::format("{}{:g}", values.empty() ? "" : ", ", v);
        same = same && v == widths.begin()->second;
      }
      effects += "      " + key + ": {joints: [" + joint_list(js) +
                 "], velocity: " + (same ? fmt::format("{:g}", widths.begin()->second) : "[" + values + "]") + "}\n";
    }
    for (auto& [key, groups] : shaped) {
      // A variant holds one entry per effect: the group with the most joints; the others noted.
      auto best = groups.begin();
      for (auto it = groups.begin(); it != groups.end(); ++it)
        if (it->second.size() > best->second.size()) best = it;
      effects += "      " + key + ": {joints: [" + joint_list(best->second) + "], " + best->first + "}\n";
      for (auto it = groups.begin(); it != groups.end(); ++it)
        if (it != best)
          notes += "    # also " + key + " on joints [" + joint_list(it->second) + "] with " + it->first +
                   " (one entry per effect in a variant: the joints above use " + best->first + ")\n";
    }
    return effects;
  }
};

}  // namespace

std::string variant_yaml(const Diagnosis& d, const std::string& name, const std::string& base) {
  VariantEntries v;
  for (const auto& e : d.selection.effects) v.add(e);
  const std::string effects = v.effects();
  std::string notes = v.notes;
  if (d.backlash_judged)
    for (const auto& f : d.backlash.findings)
      notes += fmt::format(
          "    # backlash on joint {} ({:.3f} deg of play, from the closed loop's high band): not a rigid-body "
          "term; expect chatter where its mesh torque reverses\n",
          f.joint, f.width * 180 / 3.14159265358979323846);
  if (effects.empty() && notes.empty()) return {};
  std::string y = "  " + name + ":\n";
  y += "    description: " + base + " with the effects dynid diagnose found\n";
  // The full model is every variant's starting point, not a variant robot.yaml can name.
  if (base != "full") y += "    base: " + base + "\n";
  if (!effects.empty()) y += "    effects:\n" + effects;
  y += notes;
  return y;
}

}  // namespace symoro::diagnose
