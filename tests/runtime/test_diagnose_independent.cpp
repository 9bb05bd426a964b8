// The diagnosis on logs of an arm simulated apart from the project's twin (independent_arm.hpp:
// its own integrator, velocity filter, sensor noise, measured rather than commanded current,
// and a stiffer, better damped mesh), on two robots: the CRANE-X7 (its twin.yaml describes the
// arm) and the RX-90 (a twin description built here from its modified-DH frames, random
// physical links, drives and servos of an industrial arm). The backlash stage compares the
// logs with the project's twin, which differs from this arm in all those ways:
//   - without play it names none (a plain excess over the twin once named 0.3 deg on clean
//     data);
//   - with play on two joints whose mesh torque reverses, it names those two and no other, with
//     a width of the right order (the twin's mesh, not this arm's, sets it);
//   - Coulomb friction on two joints is named there, with no Stribeck term beside it even at a
//     lax level, and gives no play;
//   - Stribeck friction beside Coulomb friction is named with it, each at its size, on a joint
//     the servo holds most of the time (CRANE-X7) and on one that never rests (RX-90); so is
//     Tustin's, a row of the effect table the diagnosis knows by its law alone, when asked for.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "independent_arm.hpp"
#include "independent_rx90.hpp"
#include "symoro/diagnose/backlash_fit.hpp"
#include "symoro/diagnose/selection.hpp"
#include "symoro/diagnose/stack_builder.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"
#include "test_support.hpp"

namespace {

using namespace symoro;
using namespace symoro::diagnose;
using twin::TwinConfig;
constexpr double kDeg = M_PI / 180;

bool verbose() { return std::getenv("SYMORO_DIAGNOSE_VERBOSE") != nullptr; }

void print(const BacklashFit& b) {
  if (!verbose()) return;
  for (Eigen::Index j = 0; j < b.measured.size(); ++j)
    std::cout << fmt::format(
        "  joint {}: measured {:.4f} null {:.4f} (floor {:.4f}, encoder noise {:.3f}) spread {:.4f}\n", j + 1,
        b.measured(j), b.simulated(j), b.floor.rms(j), b.floor.encoder_noise_per_joint(j), b.spread(j));
  std::cout << fmt::format("  encoder noise {:.3f} counts, lag {}\n", b.floor.encoder_noise, b.floor.lag);
  for (const auto& f : b.findings)
    std::cout << fmt::format("  -> play on joint {}: {:.3f} deg\n", f.joint, f.width / kDeg);
  for (const auto& n : b.notes) std::cout << "  note: " << n << "\n";
}

void print(const Selection& s) {
  if (!verbose()) return;
  for (const auto& e : s.effects) std::cout << "  -> " << e.candidate.label() << ": " << e.magnitude.text << "\n";
  for (const auto& e : s.dropped)
    std::cout << "  dropped " << e.candidate.label() << ": " << e.magnitude << " (" << e.reason << ")\n";
  std::cout << fmt::format("  held-out rmse {:.4f} -> {:.4f} N m; {}\n", s.before.heldout_total, s.after.heldout_total,
                           s.stop_reason);
}

std::vector<int> play_joints(const BacklashFit& b) {
  std::vector<int> v;
  for (const auto& f : b.findings) v.push_back(f.joint);
  std::sort(v.begin(), v.end());
  return v;
}

template <class Full>
BacklashFit backlash_stage(const io::Log& log, const TwinConfig& c, const Selection* s = nullptr) {
  const TwinConfig nominal = s ? with_selected_effects(c, *s) : c;
  const BacklashFit b = fit_backlash(symoro::robot::compiled_model<Full>(), log,
                                     trajectory::sampled_reference(log, c.controller.period), nominal);
  print(b);
  return b;
}

// Every selected effect must be one of `expected` (kind, joint), each present within `within`.
void expect_effects(const Selection& s, const std::vector<std::tuple<EffectKind, int, double>>& expected,
                    double within = 0.2) {
  for (const auto& [kind, joint, value] : expected) {
    const SelectedEffect* found = nullptr;
    for (const auto& e : s.effects)
      if (e.candidate.kind == kind && e.candidate.joint == joint) found = &e;
    ASSERT_NE(found, nullptr) << "missing " << effect_info(kind).name << " on joint " << joint;
    EXPECT_NEAR(found->magnitude.values[0], value, within * std::abs(value)) << found->magnitude.text;
  }
  for (const auto& e : s.effects) {
    bool wanted = false;
    for (const auto& [kind, joint, value] : expected) wanted |= e.candidate.kind == kind && e.candidate.joint == joint;
    EXPECT_TRUE(wanted) << "spurious " << e.candidate.label() << ": " << e.magnitude.text;
  }
}

// At a lax level, among the friction terms, no Stribeck term is named beside the Coulomb
// friction, and the Coulomb friction stands (`coulomb`: joint, N m). Before the joint's
// friction shared one velocity spread, the forward steps named one on the CRANE-X7's data,
// which the backward check (selection.hpp) then dropped.
void lax_friction_selection(const DesignStack& train, const DesignStack& heldout,
                            const std::vector<std::pair<int, double>>& coulomb) {
  SelectionOptions lax;
  lax.alpha = 0.5;
  lax.min_heldout_gain = 0.002;
  lax.min_effect_torque = 0;
  lax.candidates.only = {"coulomb", "stribeck", "offset", "viscous_asymmetry"};
  const Selection l = select_effects(train, heldout, lax);
  print(l);
  for (const auto& e : l.dropped) EXPECT_NE(e.candidate.kind, EffectKind::Coulomb) << e.candidate.label() << " dropped";
  for (const auto& e : l.effects)
    EXPECT_NE(e.candidate.kind, EffectKind::Stribeck) << e.candidate.label() << ": " << e.magnitude.text;
  for (const auto& [joint, value] : coulomb) {
    const SelectedEffect* c = nullptr;
    for (const auto& e : l.effects)
      if (e.candidate.kind == EffectKind::Coulomb && e.candidate.joint == joint) c = &e;
    ASSERT_NE(c, nullptr) << "Coulomb friction on joint " << joint << " dropped";
    EXPECT_NEAR(c->magnitude.values[0], value, 0.2 * value);
  }
}

// ---- CRANE-X7: its twin description, its designed trajectories ----

using Crane = crane_x7::Model;
using CraneReduced = crane_x7::reduced::Model;
const std::string kCrane = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";

TwinConfig crane_twin() { return twin::read_twin_config(kCrane + "/twin.yaml", Crane::nq); }

trajectory::SampledReference crane_reference(const std::string& name) {
  static const auto design = trajectory::TrajectoryDesign::read(
      kCrane + "/trajectories.yaml", std::vector<JointInfo>(Crane::joints.begin(), Crane::joints.end()));
  return trajectory::sample(design.build(name), 0.001);
}

struct CraneRuns {
  io::Log fit;
  DesignStack train, heldout;
};

// The fit log, and (stacks) the train and held-out stacks with the candidates' terms made at the
// logs' rate for `candidates` (as dynid diagnose makes them for the options it selects with).
CraneRuns crane_runs(const test::IndependentArmOptions& base, bool stacks, const CandidateOptions& candidates = {}) {
  const TwinConfig c = crane_twin();
  CraneRuns r;
  auto run = [&](const std::string& name, unsigned seed) {
    test::IndependentArmOptions o = base;
    o.seed = seed;
    return test::run_independent_arm<Crane>(c, crane_reference(name), o);
  };
  r.fit = run("AG02", 101);
  if (!stacks) return r;
  StackOptions so;
  so.interval = 0.01;
  so.cutoff = 5;
  so.candidates = candidates;
  auto stack = [&](const std::vector<std::pair<std::string, io::Log>>& logs) {
    std::vector<NamedSamples> runs;
    for (const auto& [name, log] : logs)
      runs.push_back({name, preprocess::preprocess(log, 0.001, light_preprocessing())});
    return stack_design<Crane, CraneReduced>(runs, so);
  };
  r.train = stack({{"AG02", r.fit}});
  r.heldout = stack({{"V01", run("V01", 102)}, {"V02", run("V02", 103)}, {"V03", run("V03", 104)}});
  return r;
}

TEST(DiagnoseIndependentCrane, NoPlayIsNamedOnAnArmWithoutPlay) {
  const CraneRuns r = crane_runs({}, true);
  const Selection s = select_effects(r.train, r.heldout);
  print(s);
  const BacklashFit b = backlash_stage<Crane>(r.fit, crane_twin(), &s);
  EXPECT_TRUE(b.findings.empty()) << "play named on joint " << b.findings.front().joint;
  // Against the twin description alone (its own noise, its own loop), this arm's high band is
  // well above on some joint: what named play on clean data before the null held the log's floor.
  twin::RunOptions ro;
  ro.robot = "crane_x7";
  ro.seed = 5;
  const Eigen::VectorXd plain = high_band_rms(twin::ClosedLoopTwin(symoro::robot::compiled_model<Crane>(), crane_twin())
                                                  .run(trajectory::sampled_reference(r.fit, 0.001), ro));
  int above = 0;
  for (int j = 0; j < Crane::nq; ++j) above += b.measured(j) > 1.5 * plain(j);
  EXPECT_GE(above, 1) << "the independent arm's high band is the twin's: the test tests nothing";
}

TEST(DiagnoseIndependentCrane, CoulombOnTwoJointsGetsNeitherStribeckNorPlay) {
  test::IndependentArmOptions o;
  o.coulomb = Eigen::VectorXd::Zero(Crane::nq);
  o.coulomb(5) = 0.03;
  o.coulomb(6) = 0.02;
  const CraneRuns r = crane_runs(o, true);
  const Selection s = select_effects(r.train, r.heldout);
  print(s);
  expect_effects(s, {{EffectKind::Coulomb, 6, 0.03}, {EffectKind::Coulomb, 7, 0.02}});
  const BacklashFit b = backlash_stage<Crane>(r.fit, crane_twin(), &s);
  EXPECT_TRUE(b.findings.empty()) << "play named on joint " << b.findings.front().joint;
  lax_friction_selection(r.train, r.heldout, {{6, 0.03}, {7, 0.02}});
}

// Static friction above Coulomb's (Stribeck: 0.06 N m fading over 0.1 rad/s) beside 0.05 N m
// of Coulomb friction, on joint 2: the shoulder that AG02 holds against gravity four fifths of
// the time, where the servo hunts about rest (0.03 rad/s rms). Both are named, each within
// 25 % (before one smoothing per joint: 0.055 N m of Coulomb friction alone). The arm's
// friction law is its own: a sharp tanh over 0.01 rad/s, not the columns' width.
TEST(DiagnoseIndependentCrane, StribeckBesideCoulombIsNamedWithIt) {
  test::IndependentArmOptions o;
  o.coulomb = o.stribeck = Eigen::VectorXd::Zero(Crane::nq);
  o.coulomb(1) = 0.05;
  o.stribeck(1) = 0.06;
  const CraneRuns r = crane_runs(o, true);
  const Selection s = select_effects(r.train, r.heldout);
  print(s);
  expect_effects(s, {{EffectKind::Coulomb, 2, 0.05}, {EffectKind::Stribeck, 2, 0.06}}, 0.25);
}

// Tustin's Stribeck friction, sign(qd) exp(-|qd| / vs): a row the effect table holds with its law
// alone, which the diagnosis looks for when asked (--only), averaged over the velocity spread as
// it does Stribeck's. 0.06 N m of it fading over 0.12 rad/s (on no grid of the diagnosis) beside
// 0.05 N m of Coulomb friction on joint 2, which the servo holds about rest most of the time:
// both named, each within 25 %. (Fading over 0.06 rad/s, it is hardly more than Coulomb's shape
// under the servo's 0.03 rad/s of hunting: Coulomb friction alone was named, 0.068 N m.)
TEST(DiagnoseIndependentCrane, TustinsStribeckIsNamedWhenAskedFor) {
  test::IndependentArmOptions o;
  o.coulomb = o.stribeck = Eigen::VectorXd::Zero(Crane::nq);
  o.coulomb(1) = 0.05;
  o.stribeck(1) = 0.06;
  o.stribeck_velocity = 0.12;
  o.stribeck_shape = 1.0;
  SelectionOptions asked;
  asked.candidates.only = {"coulomb", "tustin_stribeck", "offset"};
  const CraneRuns r = crane_runs(o, true, asked.candidates);
  const Selection s = select_effects(r.train, r.heldout, asked);
  print(s);
  expect_effects(s, {{EffectKind::Coulomb, 2, 0.05}, {effect_kind("tustin_stribeck"), 2, 0.06}}, 0.25);
}

TEST(DiagnoseIndependentCrane, PlayOnTwoJointsIsNamedThere) {
  test::IndependentArmOptions o;
  o.play = Eigen::VectorXd::Zero(Crane::nq);
  o.play(0) = 0.5 * kDeg;
  o.play(2) = 0.5 * kDeg;
  const CraneRuns r = crane_runs(o, false);
  const BacklashFit b = backlash_stage<Crane>(r.fit, crane_twin());
  EXPECT_EQ(play_joints(b), (std::vector<int>{1, 3}));
  // The width comes from the twin's mesh, not this arm's (stiffer, better damped): its order.
  for (const auto& f : b.findings) {
    EXPECT_GT(f.width, 0.5 * kDeg / 3) << "joint " << f.joint;
    EXPECT_LT(f.width, 0.5 * kDeg * 3) << "joint " << f.joint;
  }
}

// ---- RX-90: a twin description built from its frames ----

using Rx = rx90::Model;
using RxRigid = rx90::rigid::Model;
using test::rx90_reference;
using test::rx90_twin;

// A 40 s excitation fitted (seed 11) and another held out (seed 12), stacked at 10 ms and 5 Hz.
struct Rx90Runs {
  io::Log fit;
  DesignStack train, heldout;
};

Rx90Runs rx90_runs(const TwinConfig& c, test::IndependentArmOptions o, const CandidateOptions& candidates = {}) {
  StackOptions so;
  so.interval = 0.01;
  so.cutoff = 5;
  so.candidates = candidates;
  Rx90Runs r;
  auto stack = [&](const std::string& name, unsigned seed, io::Log* keep) {
    o.seed = seed;
    const io::Log log = test::run_independent_arm<Rx>(c, rx90_reference(name, 40, seed), o);
    if (keep) *keep = log;
    return stack_design<Rx, RxRigid>({{name, preprocess::preprocess(log, 0.001, light_preprocessing())}}, so);
  };
  r.train = stack("fit", 11, &r.fit);
  r.heldout = stack("heldout", 12, nullptr);
  return r;
}

TEST(DiagnoseIndependentRx90, PlayIsNamedOnlyWhereThereIsPlay) {
  const TwinConfig c = rx90_twin();
  const auto ref = rx90_reference("excite", 40, 5);
  test::IndependentArmOptions clean;
  const BacklashFit none = backlash_stage<Rx>(test::run_independent_arm<Rx>(c, ref, clean), c);
  EXPECT_TRUE(none.findings.empty()) << "play named on joint " << none.findings.front().joint;

  test::IndependentArmOptions o;
  o.play = Eigen::VectorXd::Zero(Rx::nq);
  o.play(0) = 0.1 * kDeg;
  o.play(4) = 0.1 * kDeg;
  const BacklashFit b = backlash_stage<Rx>(test::run_independent_arm<Rx>(c, ref, o), c);
  EXPECT_EQ(play_joints(b), (std::vector<int>{1, 5}));
  // The twin's mesh is softer and less damped than this arm's: it chatters more for the same
  // play, and the width comes out smaller (0.036 and 0.042 deg): its order only.
  for (const auto& f : b.findings) {
    EXPECT_GT(f.width, 0.1 * kDeg / 4) << "joint " << f.joint;
    EXPECT_LT(f.width, 0.1 * kDeg * 4) << "joint " << f.joint;
  }
}

TEST(DiagnoseIndependentRx90, CoulombWithoutItsColumnsIsNamedAloneWithoutPlay) {
  const TwinConfig c = rx90_twin();
  test::IndependentArmOptions o;
  o.coulomb = Eigen::VectorXd::Zero(Rx::nq);
  o.coulomb(1) = 2.0;
  o.coulomb(3) = 0.5;
  const Rx90Runs r = rx90_runs(c, o);
  const DesignStack& train = r.train;
  const DesignStack& heldout = r.heldout;
  const io::Log& fit_log = r.fit;
  const Selection s = select_effects(train, heldout);
  print(s);
  expect_effects(s, {{EffectKind::Coulomb, 2, 2.0}, {EffectKind::Coulomb, 4, 0.5}});
  const BacklashFit b = backlash_stage<Rx>(fit_log, c, &s);
  EXPECT_TRUE(b.findings.empty()) << "play named on joint " << b.findings.front().joint;
  lax_friction_selection(train, heldout, {{2, 2.0}, {4, 0.5}});
}

// Stribeck friction of another law than the columns' (exp(-(|qd| / vs)^1.5), vs = 0.08 rad/s,
// on no grid of the diagnosis) beside Coulomb friction on joint 2 of an industrial arm that
// never rests: both named within 25 % (1.72 N m at vs = 0.07); Coulomb friction alone on joint
// 4 gets no Stribeck term.
TEST(DiagnoseIndependentRx90, StribeckOfAnotherLawIsNamedBesideCoulomb) {
  const TwinConfig c = rx90_twin();
  test::IndependentArmOptions o;
  o.coulomb = o.stribeck = Eigen::VectorXd::Zero(Rx::nq);
  o.coulomb(1) = 2.0;
  o.stribeck(1) = 1.5;
  o.coulomb(3) = 0.5;
  o.stribeck_velocity = 0.08;
  o.stribeck_shape = 1.5;
  const Rx90Runs r = rx90_runs(c, o);
  const Selection s = select_effects(r.train, r.heldout);
  print(s);
  expect_effects(s, {{EffectKind::Coulomb, 2, 2.0}, {EffectKind::Stribeck, 2, 1.5}, {EffectKind::Coulomb, 4, 0.5}},
                 0.25);
}

// Tustin's Stribeck friction fading over 0.06 rad/s beside Coulomb friction on joint 2 of the
// arm that never rests, asked for: both named, each within 25 %.
TEST(DiagnoseIndependentRx90, TustinsStribeckIsNamedWhenAskedFor) {
  const TwinConfig c = rx90_twin();
  test::IndependentArmOptions o;
  o.coulomb = o.stribeck = Eigen::VectorXd::Zero(Rx::nq);
  o.coulomb(1) = 2.0;
  o.stribeck(1) = 1.5;
  o.stribeck_velocity = 0.06;
  o.stribeck_shape = 1.0;
  SelectionOptions asked;
  asked.candidates.only = {"coulomb", "tustin_stribeck", "offset"};
  const Rx90Runs r = rx90_runs(c, o, asked.candidates);
  const Selection s = select_effects(r.train, r.heldout, asked);
  print(s);
  expect_effects(s, {{EffectKind::Coulomb, 2, 2.0}, {effect_kind("tustin_stribeck"), 2, 1.5}}, 0.25);
}

}  // namespace
