#include "symoro/diagnose/backlash_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "symoro/error.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::diagnose {

twin::TwinConfig with_selected_effects(twin::TwinConfig c, const Selection& s) {
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
      default:
        break;
    }
  }
  return c;
}

BacklashFit fit_backlash(const robot::ModelHandle& full, const io::Log& measured,
                         const trajectory::SampledReference& reference, twin::TwinConfig nominal,
                         const BacklashFitOptions& options) {
  const int n = full.nq();
  BacklashFit fit;
  fit.measured = high_band_rms(measured, options);
  // No play anywhere to start with (a description may carry widths with backlash switched off).
  nominal.effects.backlash = false;
  nominal.effects.backlash_width = Eigen::VectorXd::Zero(n);
  // The null: the log's encoder noise in the loop, its unexplained torque added to the result
  // (the twin's own current noise off: the log's is that).
  fit.floor = loop_floor(measured, nominal, options);
  nominal.effects.sensor_noise = true;
  nominal.effects.encoder_noise = fit.floor.encoder_noise;
  nominal.effects.encoder_noise_per_joint = fit.floor.encoder_noise_per_joint;
  nominal.effects.current_noise = 0;
  auto simulate = [&](const twin::TwinConfig& c, std::uint64_t seed) {
    twin::RunOptions ro;
    ro.robot = full.robot();
    ro.seed = seed;
    ++fit.simulations;
    const Eigen::VectorXd loop = high_band_rms(twin::ClosedLoopTwin(full, c).run(reference, ro), options);
    return Eigen::VectorXd((loop.cwiseAbs2() + fit.floor.rms.cwiseAbs2()).cwiseSqrt());
  };
  auto judge = [&](const twin::TwinConfig& c) {
    Eigen::MatrixXd runs(n, options.seeds);
    for (int k = 0; k < options.seeds; ++k) runs.col(k) = simulate(c, options.seed + static_cast<std::uint64_t>(k));
    fit.simulated = runs.rowwise().mean();
    fit.spread =
        ((runs.colwise() - fit.simulated).array().square().rowwise().sum() / std::max(1, options.seeds - 1)).sqrt();
  };
  twin::TwinConfig c = nominal;
  if (c.effects.actuation_delay && c.effects.actuation_delay_time > 0) {
    auto mismatch = [&](double d) {
      twin::TwinConfig t = c;
      t.effects.actuation_delay_time = d;
      const Eigen::VectorXd h = simulate(t, options.seed);
      double sum = 0;
      for (int j = 0; j < n; ++j) sum += std::pow(std::log(fit.measured(j) / h(j)), 2);
      return sum;
    };
    const double g = 0.5 * (std::sqrt(5.0) - 1);
    double a = c.effects.actuation_delay_time * (1 - options.delay_range),
           b = c.effects.actuation_delay_time * (1 + options.delay_range);
    double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = mismatch(x1), f2 = mismatch(x2);
    for (int k = 0; k < options.delay_steps; ++k) {
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
      if (excess > options.sigmas * fit.spread(j) && excess > options.relative * fit.simulated(j) &&
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
    double lo = 0, hi = options.max_width;
    try {
      for (int k = 0; k < options.bisection_steps; ++k) {
        const double mid = 0.5 * (lo + hi);
        trial.effects.backlash_width(best) = mid;
        (simulate(trial, options.seed)(best) < f.measured ? lo : hi) = mid;
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
    if (f.width < 2 * options.max_width / std::pow(2.0, options.bisection_steps)) break;
    trial.effects.backlash_width(best) = f.width;
    c = trial;
    judge(c);
    f.simulated_after = fit.simulated(best);
    fit.findings.push_back(f);
  }
  return fit;
}

}  // namespace symoro::diagnose
