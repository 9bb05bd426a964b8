// Backlash from the closed loop's high band. Play in a gear lets the rotor float between the
// flanks wherever the mesh torque is small; the 1 kHz FF+PD loop then chatters, and the measured
// torque (current) gains power far above the diagnosis's 5 Hz band, where the stack's columns
// cannot see it (a linear column of the low band explains < 2 % of it). So backlash is judged
// by simulating the experiment: the robot's digital twin (its nominal description, plus the
// effects the diagnosis already selected) runs the fitting run's references in closed loop.
// A real arm's high band also holds what the twin does not model (current noise, the current
// loop, its encoders' noise): judged against the twin alone, any real arm has play. So the null
// is the twin with the log's own floor (high_band.hpp: the encoder noise estimated from the log
// put into the twin, and the torque the controller's law does not explain added to it):
//   1. a joint whose measured high-band torque rms exceeds the null's by more than the
//      simulation's own spread across noise seeds (and by a relative margin) has a candidate;
//   2. the joint with the largest excess gets the play width whose null reproduces its measured
//      high-band rms (bisection: the chatter grows with the width), and the others are
//      re-judged with it in the simulation (a neighbour's chatter couples into them);
//   3. until no joint exceeds.
// A joint whose mesh torque never reverses (a gravity-loaded elbow) never crosses its play: its
// backlash leaves no trace in either band and is not named. The width is the twin's mesh's: an
// arm whose gears are stiffer or better damped chatters less for the same play.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <fmt/format.h>

#include "symoro/diagnose/high_band.hpp"
#include "symoro/diagnose/selection.hpp"
#include "symoro/error.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::diagnose {

struct BacklashFinding {
  int joint = 0;                  // 1-based
  double width = 0;               // rad, total play
  double measured = 0;            // N m, high-band torque rms of the data
  double simulated_before = 0;    // N m, of the simulation without this joint's play (mean over seeds)
  double spread = 0;              // N m, its standard deviation over seeds
  double simulated_after = 0;     // N m, with the fitted play
};

struct BacklashFit {
  Eigen::VectorXd measured, simulated, spread;  // per joint, the final judgement (N m); simulated: the null
  LoopFloor floor;                // the log's own floor, in the null
  std::vector<BacklashFinding> findings;
  double delay = 0;               // s, the refined actuation delay (0: none was selected)
  int simulations = 0;
  std::vector<std::string> notes; // joints the twin cannot give play (said in the report)
};

// The twin description with the effects the selection named that the twin can play: Coulomb
// friction, offsets (the twin's is the external torque: minus the effect) and the delay.
inline twin::TwinConfig with_selected_effects(twin::TwinConfig c, const Selection& s) {
  const Eigen::Index n = c.rotor_inertia.size();
  for (const auto& e : s.effects) {
    const int j = e.candidate.joint - 1;
    const double v = e.magnitude.values.empty() ? 0.0 : e.magnitude.values[0];
    switch (e.candidate.kind) {
      case EffectKind::Coulomb:
        if (!c.effects.coulomb) c.effects.coulomb_torque = Eigen::VectorXd::Zero(n);
        c.effects.coulomb = true;
        c.effects.coulomb_torque(j) = v;
        break;
      case EffectKind::Offset:
        if (!c.effects.torque_offset) c.effects.offset_torque = Eigen::VectorXd::Zero(n);
        c.effects.torque_offset = true;
        c.effects.offset_torque(j) = -v;
        break;
      case EffectKind::ActuationDelay:
        c.effects.actuation_delay = true;
        c.effects.actuation_delay_time = v;
        break;
      case EffectKind::Payload:
        if (e.magnitude.values.size() == 4) {
          c.effects.payload = true;
          c.effects.payload_mass = v;
          c.effects.payload_com = Eigen::Vector3d(e.magnitude.values[1], e.magnitude.values[2], e.magnitude.values[3]);
        }
        break;
      default: break;
    }
  }
  return c;
}

// `nominal`: the robot's twin configuration with the effects already diagnosed switched on and
// every unknown one off (backlash off); `measured` the fitting run and `reference` its
// reference at every cycle (the log's own references: the motion that was logged).
template <class Full>
BacklashFit fit_backlash(const io::Log& measured, const trajectory::SampledReference& reference, twin::TwinConfig nominal,
                         const BacklashFitOptions& o = {}) {
  const int n = Full::nq;
  BacklashFit fit;
  fit.measured = high_band_rms(measured, o);
  // No play anywhere to start with (a description may carry widths with backlash switched off).
  nominal.effects.backlash = false;
  nominal.effects.backlash_width = Eigen::VectorXd::Zero(n);
  // The null: the log's encoder noise in the loop, its unexplained torque added to the result
  // (the twin's own current noise off: the log's is that).
  fit.floor = loop_floor(measured, nominal, o);
  nominal.effects.sensor_noise = true;
  nominal.effects.encoder_noise = fit.floor.encoder_noise;
  nominal.effects.encoder_noise_per_joint = fit.floor.encoder_noise_per_joint;
  nominal.effects.current_noise = 0;
  auto simulate = [&](const twin::TwinConfig& c, std::uint64_t seed) {
    twin::RunOptions ro;
    ro.robot = Full::robot_name;
    ro.seed = seed;
    ++fit.simulations;
    const Eigen::VectorXd loop = high_band_rms(twin::ClosedLoopTwin<Full>(c).run(reference, ro), o);
    return Eigen::VectorXd((loop.cwiseAbs2() + fit.floor.rms.cwiseAbs2()).cwiseSqrt());
  };
  auto judge = [&](const twin::TwinConfig& c) {
    Eigen::MatrixXd runs(n, o.seeds);
    for (int k = 0; k < o.seeds; ++k) runs.col(k) = simulate(c, o.seed + static_cast<std::uint64_t>(k));
    fit.simulated = runs.rowwise().mean();
    fit.spread = ((runs.colwise() - fit.simulated).array().square().rowwise().sum() / std::max(1, o.seeds - 1)).sqrt();
  };
  twin::TwinConfig c = nominal;
  if (c.effects.actuation_delay && c.effects.actuation_delay_time > 0) {
    auto mismatch = [&](double d) {
      twin::TwinConfig t = c;
      t.effects.actuation_delay_time = d;
      const Eigen::VectorXd h = simulate(t, o.seed);
      double sum = 0;
      for (int j = 0; j < n; ++j) sum += std::pow(std::log(fit.measured(j) / h(j)), 2);
      return sum;
    };
    const double g = 0.5 * (std::sqrt(5.0) - 1);
    double a = c.effects.actuation_delay_time * (1 - o.delay_range), b = c.effects.actuation_delay_time * (1 + o.delay_range);
    double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = mismatch(x1), f2 = mismatch(x2);
    for (int k = 0; k < o.delay_steps; ++k) {
      if (f1 < f2) {
        b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = mismatch(x1);
      } else {
        a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = mismatch(x2);
      }
    }
    c.effects.actuation_delay_time = 0.5 * (a + b);
    fit.delay = c.effects.actuation_delay_time;
  }
  judge(c);
  std::vector<bool> refused(n, false);  // joints whose play the twin's plant cannot model
  for (int step = 0; step < n; ++step) {
    // The joint with the largest significant excess, if any (joints without a rotor cannot
    // have the twin's backlash: their play is not fitted).
    int best = -1;
    double best_ratio = 0;
    for (int j = 0; j < n; ++j) {
      if (!(c.rotor_inertia(j) > 0) || c.effects.backlash_width(j) > 0 || refused[j]) continue;
      const double excess = fit.measured(j) - fit.simulated(j);
      if (excess > o.sigmas * fit.spread(j) && excess > o.relative * fit.simulated(j) &&
          excess / fit.simulated(j) > best_ratio) {
        best = j;
        best_ratio = excess / fit.simulated(j);
      }
    }
    if (best < 0) break;
    BacklashFinding f;
    f.joint = best + 1;
    f.measured = fit.measured(best);
    f.simulated_before = fit.simulated(best);
    f.spread = fit.spread(best);
    // Bisection on the width: the simulated high-band rms of this joint against the measured.
    twin::TwinConfig trial = c;
    trial.effects.backlash = true;
    double lo = 0, hi = o.max_width;
    try {
      for (int k = 0; k < o.bisection_steps; ++k) {
        const double mid = 0.5 * (lo + hi);
        trial.effects.backlash_width(best) = mid;
        (simulate(trial, o.seed)(best) < f.measured ? lo : hi) = mid;
      }
    } catch (const DataError& e) {  // e.g. a joint whose link side has no inertia in the twin
      refused[best] = true;
      fit.notes.push_back(fmt::format("joint {}: high-band excess {:.3g} N m not judged ({})", best + 1,
                                      f.measured - f.simulated_before, e.what()));
      --step;
      continue;
    }
    f.width = 0.5 * (lo + hi);
    // A width at the bisection's floor: any play at all overshoots, so play does not explain it.
    if (f.width < 2 * o.max_width / std::pow(2.0, o.bisection_steps)) break;
    trial.effects.backlash_width(best) = f.width;
    c = trial;
    judge(c);
    f.simulated_after = fit.simulated(best);
    fit.findings.push_back(f);
  }
  return fit;
}

}  // namespace symoro::diagnose
