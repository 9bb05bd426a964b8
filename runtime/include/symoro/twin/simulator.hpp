// The closed-loop digital twin: the plant driven by the paper's FF+PD controller through the
// realization layer of a DYNAMIXEL arm, producing the log a real run would produce.
//
// One control cycle k (nominal period T, start t_k = k T + jitter):
//   t_k        the encoders are sampled (link-side, quantized, optional noise) and the
//              servos report their present current (quantized, optional noise); the log row
//              stamps t_k, and its torque is the one computed from that current with the
//              nominal torque constants, as on the real arm.
//   t_k + d    after the bus round trip d (reading 8 encoders and writing 8 commands) the new
//              current commands take effect and are held until the next ones (sample and
//              hold adds about T/2, so the total delay is about d + T/2). With the
//              actuation_delay effect the torque follows the command a further time later,
//              while the servo keeps reporting the commanded current.
// A dropped cycle (failed read) writes no row and the controller reuses its last measurement.
// Before t = 0 the controller holds the first reference for a pre-roll (not logged), as the
// real arm holds its start posture before a run.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <utility>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/control/ffpd.hpp"
#include "symoro/io/log.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/trajectory/trajectory.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/plant.hpp"
#include "symoro/twin/random.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::twin {

struct RunOptions {
  std::string robot;
  int trial = 1;
  std::uint64_t seed = 1;   // the run's own seed (see run_seed)
  double pre_roll = 0.5;    // s of holding the start posture before logging
};

struct RunStats {
  double simulated = 0;     // s of logged motion
  double wall = 0;          // s of computation
  int cycles = 0, dropped = 0, saturated = 0;  // saturated: cycles with a current at its limit
  Eigen::VectorXd max_error, rms_error;        // true q_ref - q, rad, per joint
  Eigen::VectorXd max_torque;                  // |applied motor torque|, N m, per joint
};

control::FfpdGains controller_gains(const TwinConfig& c);

template <class Model>
class ClosedLoopTwin {
 public:
  static constexpr int n = Model::nq;
  using Vec = Eigen::Matrix<double, n, 1>;

  explicit ClosedLoopTwin(TwinConfig config) : c_(std::move(config)), truth_(make_truth<Model>(c_)) {
    if (static_cast<int>(c_.servos.size()) != n) throw DataError(c_.path, 0, "servos: one per joint needed");
    for (const auto& j : Model::joints) names_.push_back(j.name);
  }

  const TwinConfig& config() const { return c_; }

  // What a log records about the twin that made it: the configuration file, its fingerprint
  // and the effects switched on (a dataset reruns a run whose notes differ).
  std::string notes() const {
    std::string enabled;
    for (const auto& s : c_.effects.enabled()) enabled += (enabled.empty() ? "" : ", ") + s;
    return "digital twin (" + c_.path + ", config " + c_.fingerprint + "); effects: " + (enabled.empty() ? "none" : enabled);
  }
  const Truth<Model>& truth() const { return truth_; }

  io::Log run(const trajectory::Trajectory& traj, const RunOptions& opt, RunStats* stats = nullptr) const {
    if (traj.joints() != n)
      throw DataError(traj.name, 0, "the trajectory has " + std::to_string(traj.joints()) + " joints, the robot " + std::to_string(n));
    return run(trajectory::sample(traj, c_.controller.period), opt, stats);
  }

  // The same with the reference of every cycle given (e.g. a log's own references: the motion
  // that was logged, replayed). Its period must be the controller's.
  io::Log run(const trajectory::SampledReference& ref, const RunOptions& opt, RunStats* stats = nullptr) const {
    const auto wall0 = std::chrono::steady_clock::now();
    if (ref.joints() != n)
      throw DataError(ref.name, 0, "the reference has " + std::to_string(ref.joints()) + " joints, the robot " + std::to_string(n));
    if (!(std::abs(ref.period - c_.controller.period) <= 1e-9 * c_.controller.period) || ref.cycles() < 1)
      throw DataError(ref.name, 0, "the reference is sampled every " + std::to_string(ref.period) + " s, the controller runs every " +
                                       std::to_string(c_.controller.period) + " s");
    const Effects& e = c_.effects;
    const double T = c_.controller.period, d = c_.controller.communication_delay;
    const int K = ref.cycles() - 1;
    Random rng(opt.seed);

    // Servo constants.
    Vec kt, kt_true, unit, limit, lsb;
    for (int j = 0; j < n; ++j) {
      const Servo& s = c_.servos[j];
      kt(j) = s.torque_constant;
      kt_true(j) = s.torque_constant * (e.torque_constant_error ? e.torque_constant_scale(j) : 1.0);
      unit(j) = s.current_unit;
      limit(j) = std::floor(s.current_limit / s.current_unit) * s.current_unit;
      lsb(j) = 2 * 3.14159265358979323846 / s.encoder_counts;
    }
    auto encoder = [&](const Vec& q) {
      Vec m;
      for (int j = 0; j < n; ++j) {
        const double sd = e.encoder_noise_per_joint.size() == n ? e.encoder_noise_per_joint(j) : e.encoder_noise;
        const double noise = e.sensor_noise ? sd * rng.normal() : 0.0;
        m(j) = std::round(q(j) / lsb(j) + noise) * lsb(j);
      }
      return m;
    };
    auto current_command = [&](const Eigen::VectorXd& u, bool& saturated) {
      Vec i;
      for (int j = 0; j < n; ++j) {
        i(j) = std::round(u(j) / kt(j) / unit(j)) * unit(j);
        if (std::abs(i(j)) >= limit(j)) {
          i(j) = std::copysign(limit(j), i(j));
          saturated = true;
        }
      }
      return i;
    };

    // References per cycle (the controller steps through them by cycle count).
    Eigen::VectorXd qr(n), qdr(n), qddr(n);
    qr = ref.q.col(0), qdr = ref.qd.col(0), qddr = ref.qdd.col(0);
    Plant<Model> plant(truth_, c_, Vec(qr));
    control::FfpdController ctrl(controller_gains(c_));
    Vec q_meas = encoder(plant.q());
    ctrl.reset(q_meas);
    Vec current = Vec::Zero();  // what the servos report (and the controller commanded)
    bool sat = false;
    // The current that makes torque: `current` itself, or with the actuation delay, the
    // commands in the order they went out, each taking effect `lag` after it.
    const double lag = e.actuation_delay ? e.actuation_delay_time : 0.0;
    Vec applied = Vec::Zero();
    std::deque<std::pair<double, Vec>> pending;
    double clock = -static_cast<double>(std::llround(opt.pre_roll / T)) * T;  // the pre-roll starts there
    auto drive = [&](double dt) {
      const double end = clock + dt;
      while (!pending.empty() && pending.front().first < end) {
        if (pending.front().first > clock) {
          plant.advance(pending.front().first - clock, kt_true.cwiseProduct(applied));
          clock = pending.front().first;
        }
        applied = pending.front().second;
        pending.pop_front();
      }
      if (end > clock) plant.advance(end - clock, kt_true.cwiseProduct(applied));
      clock = end;
    };
    auto command = [&](const Vec& c) {
      current = c;
      pending.emplace_back(clock + lag, c);
    };

    // Pre-roll: hold the first reference so the run starts from the held posture.
    const int pre = static_cast<int>(std::llround(opt.pre_roll / T));
    for (int k = 0; k < pre; ++k) {
      q_meas = encoder(plant.q());
      const Vec u_cmd = current_command(ctrl.update(q_meas, qr, qdr, qddr), sat);
      drive(d);
      command(u_cmd);
      drive(T - d);
    }

    io::Log log;
    log.meta.robot = opt.robot;
    log.meta.trajectory = ref.name;
    log.meta.trial = opt.trial;
    log.meta.seed = opt.seed;
    log.meta.source = "twin";
    log.meta.sample_time = T;
    log.meta.joints = names_;
    log.meta.notes = notes();
    const int rows_max = K + 1;
    log.time.resize(rows_max);
    for (Eigen::MatrixXd* m : {&log.q, &log.qd, &log.tau, &log.q_ref, &log.qd_ref, &log.qdd_ref}) m->resize(rows_max, n);

    RunStats st;
    st.max_error = Eigen::VectorXd::Zero(n);
    st.rms_error = Eigen::VectorXd::Zero(n);
    st.max_torque = Eigen::VectorXd::Zero(n);
    int rows = 0, drop_left = 0;
    double t_now = 0, t_start_next = 0;
    for (int k = 0; k <= K; ++k) {
      // The cycle starts at its jittered instant, never before the previous command went out.
      double t_k = k * T;
      if (e.timestamp_jitter && k > 0)
        t_k += std::clamp(e.jitter_std * rng.normal(), -e.jitter_max, e.jitter_max);
      t_k = std::max(t_k, t_start_next);
      drive(t_k - t_now);
      t_now = t_k;

      qr = ref.q.col(k), qdr = ref.qd.col(k), qddr = ref.qdd.col(k);
      const Vec q_true = plant.q();
      const Vec err = Vec(qr) - q_true;
      st.max_error = st.max_error.cwiseMax(err.cwiseAbs());
      st.rms_error += err.cwiseAbs2();
      st.max_torque = st.max_torque.cwiseMax(kt_true.cwiseProduct(applied).cwiseAbs());

      bool dropped = false;
      if (e.dropped_samples && k > 0 && k < K) {
        if (drop_left == 0 && rng.uniform() < e.drop_probability)
          drop_left = 1 + static_cast<int>(rng.uniform() * e.drop_max_burst);
        if (drop_left > 0) {
          dropped = true;
          --drop_left;
        }
      }
      Vec tau_logged;
      if (!dropped) {
        q_meas = encoder(q_true);
        for (int j = 0; j < n; ++j) {
          const double noise = e.sensor_noise ? e.current_noise * rng.normal() : 0.0;
          tau_logged(j) = kt(j) * std::round((current(j) + noise) / unit(j)) * unit(j);
        }
      } else {
        ++st.dropped;
      }
      bool cycle_sat = false;
      const Vec cmd = current_command(ctrl.update(q_meas, qr, qdr, qddr), cycle_sat);
      st.saturated += cycle_sat;
      if (!dropped) {
        log.time(rows) = t_k;
        log.q.row(rows) = q_meas.transpose();
        log.qd.row(rows) = ctrl.velocity().transpose();
        log.tau.row(rows) = tau_logged.transpose();
        log.q_ref.row(rows) = qr.transpose();
        log.qd_ref.row(rows) = qdr.transpose();
        log.qdd_ref.row(rows) = qddr.transpose();
        ++rows;
      }
      drive(d);
      t_now = t_k + d;
      command(cmd);
      t_start_next = t_now + 1e-6;
    }
    log.time.conservativeResize(rows);
    for (Eigen::MatrixXd* m : {&log.q, &log.qd, &log.tau, &log.q_ref, &log.qd_ref, &log.qdd_ref})
      m->conservativeResize(rows, n);

    st.cycles = K + 1;
    st.rms_error = (st.rms_error / double(K + 1)).cwiseSqrt();
    st.simulated = K * T;
    st.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    if (stats) *stats = st;
    return log;
  }

 private:
  TwinConfig c_;
  Truth<Model> truth_;
  std::vector<std::string> names_;
};

}  // namespace symoro::twin
