#include "symoro/twin/simulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <utility>

#include "symoro/error.hpp"
#include "symoro/twin/plant.hpp"

namespace symoro::twin {

ClosedLoopTwin::ClosedLoopTwin(robot::ModelHandle model, TwinConfig config)
    : model_(std::move(model)), c_(std::move(config)) {
  const int n = model_.nq();
  if (static_cast<int>(c_.servos.size()) != n) throw DataError(c_.path, 0, "servos: one per joint needed");
  if (c_.rotor_inertia.size() != n || c_.viscous.size() != n)
    throw DataError(c_.path, 0,
                    "the twin is read for " + std::to_string(c_.rotor_inertia.size()) + " joints, robot '" +
                        model_.robot() + "' has " + std::to_string(n));
  truth_ = make_truth(model_, c_);
  for (const auto& j : model_.joints()) names_.push_back(j.name);
}

std::string ClosedLoopTwin::notes() const {
  std::string enabled;
  for (const auto& s : c_.effects.enabled()) enabled += (enabled.empty() ? "" : ", ") + s;
  return "digital twin (" + c_.path + ", config " + c_.fingerprint +
         "); effects: " + (enabled.empty() ? "none" : enabled);
}

io::Log ClosedLoopTwin::run(const trajectory::Trajectory& traj, const RunOptions& opt, RunStats* stats) const {
  const int n = joints();
  if (traj.joints() != n)
    throw DataError(traj.name, 0,
                    "the trajectory has " + std::to_string(traj.joints()) + " joints, the robot " + std::to_string(n));
  return run(trajectory::sample(traj, c_.controller.period), opt, stats);
}

namespace {

using Vec = Eigen::VectorXd;

// The servos as the controller sees them: encoders that quantize q (with noise when enabled),
// current commands in the servo's units, saturated at its limit, and the torque constant the
// controller assumes beside the true one (a torque-constant error).
struct Servos {
  Servos(const TwinConfig& c, int n, Random& rng) : e(c.effects), n(n), rng(rng) {
    kt.resize(n), kt_true.resize(n), unit.resize(n), limit.resize(n), lsb.resize(n);
    for (int j = 0; j < n; ++j) {
      const Servo& s = c.servos[j];
      kt(j) = s.torque_constant;
      kt_true(j) = s.torque_constant * (e.torque_constant_error ? e.torque_constant_scale(j) : 1.0);
      unit(j) = s.current_unit;
      limit(j) = std::floor(s.current_limit / s.current_unit) * s.current_unit;
      lsb(j) = 2 * 3.14159265358979323846 / s.encoder_counts;
    }
  }
  // The encoders' reading of q.
  void encoder(const Eigen::Ref<const Vec>& q, Vec& m) {
    for (int j = 0; j < n; ++j) {
      const double sd = e.encoder_noise_per_joint.size() == n ? e.encoder_noise_per_joint(j) : e.encoder_noise;
      const double noise = e.sensor_noise ? sd * rng.normal() : 0.0;
      m(j) = std::round(q(j) / lsb(j) + noise) * lsb(j);
    }
  }
  // The current commands for the controller's torques u.
  void current_command(const Vec& u, Vec& i, bool& saturated) const {
    for (int j = 0; j < n; ++j) {
      i(j) = std::round(u(j) / kt(j) / unit(j)) * unit(j);
      if (std::abs(i(j)) >= limit(j)) {
        i(j) = std::copysign(limit(j), i(j));
        saturated = true;
      }
    }
  }
  // The torque the servos log for the current they report (with current noise when enabled).
  void logged_torque(const Vec& current, Vec& tau) {
    for (int j = 0; j < n; ++j) {
      const double noise = e.sensor_noise ? e.current_noise * rng.normal() : 0.0;
      tau(j) = kt(j) * std::round((current(j) + noise) / unit(j)) * unit(j);
    }
  }

  const Effects& e;
  int n;
  Random& rng;
  Vec kt, kt_true, unit, limit, lsb;
};

// The plant driven by the commanded currents: `current` is what the servos report (and the
// controller commanded); the current that makes torque is that one, or with the actuation
// delay, the commands in the order they went out, each taking effect `lag` after it.
struct Actuation {
  Actuation(Plant& plant, const Vec& kt_true, double lag, double clock)
      : plant(plant),
        kt_true(kt_true),
        lag(lag),
        clock(clock),
        current(Vec::Zero(kt_true.size())),
        applied(Vec::Zero(kt_true.size())),
        torque(kt_true.size()) {}
  // Advances the plant by dt, applying each pending command when it takes effect.
  void drive(double dt) {
    const double end = clock + dt;
    while (!pending.empty() && pending.front().first < end) {
      if (pending.front().first > clock) {
        torque = kt_true.cwiseProduct(applied);
        plant.advance(pending.front().first - clock, torque);
        clock = pending.front().first;
      }
      applied = pending.front().second;
      pending.pop_front();
    }
    if (end > clock) {
      torque = kt_true.cwiseProduct(applied);
      plant.advance(end - clock, torque);
    }
    clock = end;
  }
  void command(const Vec& c) {
    current = c;
    pending.emplace_back(clock + lag, c);
  }

  Plant& plant;
  const Vec& kt_true;
  double lag, clock;
  Vec current, applied, torque;
  std::deque<std::pair<double, Vec>> pending;
};

// A log of up to `rows` cycles of the twin, described as the run's.
io::Log empty_log(const trajectory::SampledReference& ref, const RunOptions& opt,
                  const std::vector<std::string>& joints, const std::string& notes, double sample_time, int rows) {
  io::Log log;
  log.meta.robot = opt.robot;
  log.meta.trajectory = ref.name;
  log.meta.trial = opt.trial;
  log.meta.seed = opt.seed;
  log.meta.source = "twin";
  log.meta.sample_time = sample_time;
  log.meta.joints = joints;
  log.meta.notes = notes;
  log.time.resize(rows);
  for (Eigen::MatrixXd* m : {&log.q, &log.qd, &log.tau, &log.q_ref, &log.qd_ref, &log.qdd_ref})
    m->resize(rows, static_cast<Eigen::Index>(joints.size()));
  return log;
}

// The reference must have the robot's joints and the controller's period.
void check_reference(const trajectory::SampledReference& ref, int n, double period) {
  if (ref.joints() != n)
    throw DataError(ref.name, 0,
                    "the reference has " + std::to_string(ref.joints()) + " joints, the robot " + std::to_string(n));
  if (!(std::abs(ref.period - period) <= 1e-9 * period) || ref.cycles() < 1)
    throw DataError(ref.name, 0,
                    "the reference is sampled every " + std::to_string(ref.period) + " s, the controller runs every " +
                        std::to_string(period) + " s");
}

// Whether this cycle's sample is lost: a burst of 1 to drop_max_burst starts with probability
// drop_probability; `left` counts the burst's samples still to drop.
bool drops(const Effects& e, Random& rng, int& left) {
  if (left == 0 && rng.uniform() < e.drop_probability) left = 1 + static_cast<int>(rng.uniform() * e.drop_max_burst);
  if (left == 0) return false;
  --left;
  return true;
}

void log_row(io::Log& log, int row, double t, const Vec& q, const Vec& qd, const Vec& tau, const Vec& qr,
             const Vec& qdr, const Vec& qddr) {
  log.time(row) = t;
  log.q.row(row) = q.transpose();
  log.qd.row(row) = qd.transpose();
  log.tau.row(row) = tau.transpose();
  log.q_ref.row(row) = qr.transpose();
  log.qd_ref.row(row) = qdr.transpose();
  log.qdd_ref.row(row) = qddr.transpose();
}

}  // namespace

io::Log ClosedLoopTwin::run(const trajectory::SampledReference& ref, const RunOptions& opt, RunStats* stats) const {
  const auto wall0 = std::chrono::steady_clock::now();
  const int n = joints();
  check_reference(ref, n, c_.controller.period);
  const Effects& e = c_.effects;
  const double T = c_.controller.period, d = c_.controller.communication_delay;
  const int K = ref.cycles() - 1;
  Random rng(opt.seed);
  Servos servos(c_, n, rng);  // draws the sensors' noise from rng

  // References per cycle (the controller steps through them by cycle count).
  Vec qr = ref.q.col(0), qdr = ref.qd.col(0), qddr = ref.qdd.col(0);
  Plant plant(model_, truth_, c_, qr);
  plant.set_time(-static_cast<double>(std::llround(opt.pre_roll / T)) * T);  // log time: the pre-roll's start
  control::FfpdController ctrl(controller_gains(c_));
  Vec q_meas(n), q_true(n), u_cmd(n);
  servos.encoder(plant.q(), q_meas);
  ctrl.reset(q_meas);
  bool sat = false;
  const int pre = static_cast<int>(std::llround(opt.pre_roll / T));
  Actuation act(plant, servos.kt_true, e.actuation_delay ? e.actuation_delay_time : 0.0,
                -static_cast<double>(pre) * T);  // the pre-roll starts there

  // Pre-roll: hold the first reference so the run starts from the held posture.
  for (int k = 0; k < pre; ++k) {
    servos.encoder(plant.q(), q_meas);
    servos.current_command(ctrl.update(q_meas, qr, qdr, qddr), u_cmd, sat);
    act.drive(d);
    act.command(u_cmd);
    act.drive(T - d);
  }

  io::Log log = empty_log(ref, opt, names_, notes(), T, K + 1);
  RunStats st;
  st.max_error = Vec::Zero(n);
  st.rms_error = Vec::Zero(n);
  st.max_torque = Vec::Zero(n);
  Vec tau_logged(n), cmd(n), err(n);
  int rows = 0, drop_left = 0;
  double t_now = 0, t_start_next = 0;
  for (int k = 0; k <= K; ++k) {
    // The cycle starts at its jittered instant, never before the previous command went out.
    double t_k = k * T;
    if (e.timestamp_jitter && k > 0) t_k += std::clamp(e.jitter_std * rng.normal(), -e.jitter_max, e.jitter_max);
    t_k = std::max(t_k, t_start_next);
    act.drive(t_k - t_now);
    t_now = t_k;

    qr = ref.q.col(k), qdr = ref.qd.col(k), qddr = ref.qdd.col(k);
    q_true = plant.q();
    err = qr - q_true;
    st.max_error = st.max_error.cwiseMax(err.cwiseAbs());
    st.rms_error += err.cwiseAbs2();
    st.max_torque = st.max_torque.cwiseMax(servos.kt_true.cwiseProduct(act.applied).cwiseAbs());

    const bool dropped = e.dropped_samples && k > 0 && k < K && drops(e, rng, drop_left);
    if (!dropped) {
      servos.encoder(q_true, q_meas);
      servos.logged_torque(act.current, tau_logged);
    } else {
      ++st.dropped;
    }
    bool cycle_sat = false;
    servos.current_command(ctrl.update(q_meas, qr, qdr, qddr), cmd, cycle_sat);
    st.saturated += cycle_sat;
    if (!dropped) log_row(log, rows++, t_k, q_meas, ctrl.velocity(), tau_logged, qr, qdr, qddr);
    act.drive(d);
    t_now = t_k + d;
    act.command(cmd);
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

}  // namespace symoro::twin
