// An arm in closed loop simulated apart from the project's twin (twin/simulator.hpp), for the
// diagnosis's tests: the same rigid-body truth, but its own integrator, its own servo loop and
// its own sensors, so that what the twin does not model of a real arm's high band is there:
//   plant   the generated model's forward dynamics, semi-implicit Euler at 0.1 ms (the twin
//           integrates its own way); a joint with play gets a rotor (inertia, viscous friction)
//           coupled to its link through a dead zone and a stiff damped contact at 150 Hz,
//           damping ratio 0.25 (the twin's mesh: 100 Hz, 0.1); optional smooth Coulomb and
//           Stribeck friction on the links;
//   loop    1 kHz FF+PD with the controller description's gains, but the velocity is a backward
//           difference through a 80 Hz first-order low-pass (the twin: Tustin's pseudo-derivative
//           with Tf); the command takes effect after the bus delay and is held;
//   contact optional external torque pulses on the links, which nothing in the log records (the
//           momentum observer's tests);
//   sensors the encoder is quantized with 0.3 counts of noise; the logged torque is the current
//           the servo *measures*: the applied current plus 1.5 current units of noise, quantized
//           (the twin logs the commanded current).
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/io/log.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::test {

// An external torque on one joint's link (a contact): `torque` N m from `start` for `duration` s
// of log time, with 2 ms linear ramps inside that span.
struct TorquePulse {
  int joint = 0;  // 0-based
  double start = 0, duration = 0, torque = 0;
  double at(double t) const {
    const double ramp = 0.002, in = t - start, left = start + duration - t;
    if (in <= 0 || left <= 0) return 0;
    return torque * std::min({1.0, in / ramp, left / ramp});
  }
};

struct IndependentArmOptions {
  Eigen::VectorXd play;     // rad, total play per joint (empty or 0: rigid)
  Eigen::VectorXd coulomb;  // N m, smooth Coulomb friction at the links (empty: none)
  // N m, static friction above Coulomb's that fades with speed, exp(-(|qd|/vs)^shape) (empty: none)
  Eigen::VectorXd stribeck;
  double stribeck_velocity = 0.1, stribeck_shape = 2;
  double mesh_frequency = 150, mesh_damping = 0.25;
  double velocity_cutoff = 80;  // Hz
  double encoder_noise = 0.3;   // counts
  double current_noise = 1.5;   // current units
  double step = 1e-4;           // s
  double pre_roll = 0.5;        // s holding the first reference, not logged
  unsigned seed = 1;
  std::vector<TorquePulse> pulses;
};

// Runs `ref` on the arm that `c` describes (its chain, drives, servos and controller gains;
// its effects are ignored: the options say what the arm has) and returns the log.
template <class Model>
io::Log run_independent_arm(const twin::TwinConfig& c, const trajectory::SampledReference& ref,
                            const IndependentArmOptions& o) {
  constexpr int n = Model::nq;
  using Vec = Eigen::Matrix<double, n, 1>;
  std::mt19937 gen(o.seed);
  std::normal_distribution<double> gauss(0, 1);
  const Vec play = o.play.size() ? Vec(o.play) : Vec::Zero();
  const Vec coulomb = o.coulomb.size() ? Vec(o.coulomb) : Vec::Zero();
  const Vec stribeck = o.stribeck.size() ? Vec(o.stribeck) : Vec::Zero();
  // The links' friction: smooth through zero speed (tanh over 0.01 rad/s), so that the
  // integrator needs no stick-slip logic.
  auto friction = [&](int j, double v) {
    return (coulomb(j) + stribeck(j) * std::exp(-std::pow(std::abs(v) / o.stribeck_velocity, o.stribeck_shape))) *
           std::tanh(v / 0.01);
  };
  // The links' parameters: rotors and viscous friction of joints with play move to their rotors.
  twin::TwinConfig links = c;
  links.effects.disable_all();
  links.effects.backlash = true;
  links.effects.backlash_width = play;
  const twin::Truth truth = twin::make_truth(symoro::robot::compiled_model<Model>(), links);
  const Eigen::Matrix<double, Model::np, 1> phi = truth.phi_links;
  Vec kt, unit, limit, lsb, ia, fv, stiffness, damping;
  for (int j = 0; j < n; ++j) {
    kt(j) = c.servos[j].torque_constant;
    unit(j) = c.servos[j].current_unit;
    limit(j) = c.servos[j].current_limit;
    lsb(j) = 2 * M_PI / c.servos[j].encoder_counts;
    ia(j) = c.rotor_inertia(j);
    fv(j) = c.viscous(j);
  }
  Vec q = ref.q.col(0), qd = Vec::Zero(), qm = q, qdm = Vec::Zero();
  {
    // The link's effective inertia at the joint (1 / (M^-1)_jj: the others free), so that rotor
    // and link ring at mesh_frequency.
    Eigen::Matrix<double, n, n> M;
    Model::inertia(q, phi, M);
    const Eigen::Matrix<double, n, n> Minv = M.inverse();
    for (int j = 0; j < n; ++j) {
      const double link = 1 / Minv(j, j);
      const double w = 2 * M_PI * o.mesh_frequency, reduced = ia(j) * link / (ia(j) + link);
      stiffness(j) = reduced * w * w;
      damping(j) = 2 * o.mesh_damping * std::sqrt(stiffness(j) * reduced);
    }
  }
  double now = -o.pre_roll;  // log time
  auto advance = [&](double dt, const Vec& motor) {
    const int steps = std::max(1, static_cast<int>(std::ceil(dt / o.step - 1e-9)));
    const double h = dt / steps;
    for (int s = 0; s < steps; ++s, now += h) {
      Vec tau = motor, tm = Vec::Zero();
      for (int j = 0; j < n; ++j) {
        tau(j) -= friction(j, qd(j));
        if (!(play(j) > 0)) continue;
        const double gap = qm(j) - q(j), half = play(j) / 2;
        double mesh = 0;
        if (std::abs(gap) > half) {
          mesh = stiffness(j) * (gap - std::copysign(half, gap)) + damping(j) * (qdm(j) - qd(j));
          if (mesh * gap < 0) mesh = 0;  // a contact pushes, never pulls
        }
        tm(j) = motor(j) - fv(j) * qdm(j) - mesh;
        tau(j) = mesh - friction(j, qd(j));
      }
      for (const TorquePulse& p : o.pulses) tau(p.joint) += p.at(now + 0.5 * h);
      Vec qdd;
      Model::forward_dynamics(q, qd, tau, phi, qdd);
      qd += h * qdd;
      q += h * qd;
      for (int j = 0; j < n; ++j) {
        if (play(j) > 0) {
          qdm(j) += h * tm(j) / ia(j);
          qm(j) += h * qdm(j);
        } else {
          qm(j) = q(j), qdm(j) = qd(j);
        }
      }
    }
  };
  const control::FfpdGains g = c.controller.gains();
  const double T = c.controller.period, d = c.controller.communication_delay;
  const double alpha = std::exp(-2 * M_PI * o.velocity_cutoff * T);
  auto encoder = [&] {
    Vec m;
    for (int j = 0; j < n; ++j) m(j) = std::round(q(j) / lsb(j) + o.encoder_noise * gauss(gen)) * lsb(j);
    return m;
  };
  Vec q_prev = encoder(), v = Vec::Zero(), applied = Vec::Zero();
  auto cycle = [&](int k, io::Log* log, int row) {
    const Vec qr = ref.q.col(k), qdr = ref.qd.col(k), qddr = ref.qdd.col(k);
    const Vec qe = encoder();
    v = alpha * v + (1 - alpha) * (qe - q_prev) / T;
    q_prev = qe;
    Vec cmd;
    for (int j = 0; j < n; ++j) {
      const double u =
          g.inertia(j) * (g.kv(j) * (qdr(j) - v(j)) + g.kp(j) * (qr(j) - qe(j)) + qddr(j)) + g.damping(j) * qdr(j);
      cmd(j) = std::clamp(std::round(u / kt(j) / unit(j)) * unit(j), -limit(j), limit(j));
    }
    if (log) {
      log->time(row) = k * T;
      log->q.row(row) = qe.transpose();
      log->qd.row(row) = v.transpose();
      for (int j = 0; j < n; ++j)
        log->tau(row, j) =
            kt(j) * std::round((applied(j) + o.current_noise * unit(j) * gauss(gen)) / unit(j)) * unit(j);
      log->q_ref.row(row) = qr.transpose();
      log->qd_ref.row(row) = qdr.transpose();
      log->qdd_ref.row(row) = qddr.transpose();
    }
    advance(d, kt.cwiseProduct(applied));
    applied = cmd;
    advance(T - d, kt.cwiseProduct(applied));
  };
  const int pre_roll = static_cast<int>(std::llround(o.pre_roll / T));
  now = -pre_roll * T;
  for (int k = 0; k < pre_roll; ++k) cycle(0, nullptr, 0);
  now = 0;  // round-off of the pre-roll's steps
  io::Log log;
  log.meta.robot = Model::robot_name;
  log.meta.trajectory = ref.name;
  log.meta.trial = 1;
  log.meta.source = "robot";
  log.meta.sample_time = T;
  for (const auto& J : Model::joints) log.meta.joints.emplace_back(J.name);
  const int K = ref.cycles();
  log.time.resize(K);
  for (Eigen::MatrixXd* m : {&log.q, &log.qd, &log.tau, &log.q_ref, &log.qd_ref, &log.qdd_ref}) m->resize(K, n);
  for (int k = 0; k < K; ++k) cycle(k, &log, k);
  return log;
}

}  // namespace symoro::test
