// The momentum observer (symoro/observer/): its residual against the first-order lag of an
// external torque derived by hand, on exact logs of the generated models (CRANE-X7 and RX-90);
// and collision detection on logs of the independent arm (independent_arm.hpp: its own
// integrator, servo loop, quantized and noisy sensors, Coulomb friction the model does not hold),
// with thresholds calibrated on other runs without contact; and on the project's twin, which
// gains a contact from twin.yaml (effects: contact).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "independent_arm.hpp"
#include "independent_rx90.hpp"
#include "symoro/error.hpp"
#include "symoro/observer/collision_detection.hpp"
#include "symoro/observer/momentum_observer.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace {

using namespace symoro;
using Crane = crane_x7::Model;
using Rx = rx90::Model;

// ---- The residual against the hand-derived response --------------------------------------

// A log of Model driven along smooth cosines by a continuous PD about its own inverse dynamics,
// with `pulse` acting on the links and absent from the logged torque. RK4 at 0.1 ms; q, qd and
// the commanded torque logged exactly every 1 ms.
template <class Model>
io::Log exact_log(const Eigen::VectorXd& phi, const test::TorquePulse& pulse, double seconds) {
  constexpr int n = Model::nq;
  using Vec = Eigen::Matrix<double, n, 1>;
  Vec mid, amp;
  for (int j = 0; j < n; ++j) {
    const auto& J = Model::joints[j];
    mid(j) = 0.5 * (J.lower + J.upper);
    amp(j) = 0.15 * (J.upper - J.lower);
  }
  const auto reference = [&](double t, Vec& q, Vec& qd, Vec& qdd) {
    for (int j = 0; j < n; ++j) {
      const double w = 2 * M_PI * (0.2 + 0.05 * j);
      q(j) = mid(j) + amp(j) * (1 - std::cos(w * t));
      qd(j) = amp(j) * w * std::sin(w * t);
      qdd(j) = amp(j) * w * w * std::cos(w * t);
    }
  };
  const auto command = [&](double t, const Vec& q, const Vec& qd) {
    Vec qr, qdr, qddr, tau;
    reference(t, qr, qdr, qddr);
    const Vec a = qddr + 400 * (qr - q) + 40 * (qdr - qd);
    Model::inverse_dynamics(q, qd, a, phi, tau);
    return tau;
  };
  const auto acceleration = [&](double t, const Vec& q, const Vec& qd) {
    Vec tau = command(t, q, qd), qdd;
    tau(pulse.joint) += pulse.at(t);
    Model::forward_dynamics(q, qd, tau, phi, qdd);
    return qdd;
  };
  const double T = 0.001, h = 1e-4;
  const int K = static_cast<int>(std::lround(seconds / T)) + 1, sub = static_cast<int>(std::lround(T / h));
  io::Log log;
  log.meta.robot = Model::robot_name;
  log.meta.source = "robot";
  log.meta.sample_time = T;
  log.time.resize(K);
  log.q.resize(K, n), log.qd.resize(K, n), log.tau.resize(K, n);
  Vec q, qd, qdd;
  reference(0, q, qd, qdd);
  for (int k = 0; k < K; ++k) {
    log.time(k) = k * T;
    log.q.row(k) = q.transpose();
    log.qd.row(k) = qd.transpose();
    log.tau.row(k) = command(k * T, q, qd).transpose();
    for (int s = 0; s < sub; ++s) {
      const double t = k * T + s * h;
      const Vec k1q = qd, k1v = acceleration(t, q, qd);
      const Vec k2q = qd + 0.5 * h * k1v, k2v = acceleration(t + 0.5 * h, q + 0.5 * h * k1q, k2q);
      const Vec k3q = qd + 0.5 * h * k2v, k3v = acceleration(t + 0.5 * h, q + 0.5 * h * k2q, k3q);
      const Vec k4q = qd + h * k3v, k4v = acceleration(t + h, q + h * k3q, k4q);
      q += h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
      qd += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
  }
  return log;
}

// dr/dt = K (tau_ext - r) from r(0) = 0, integrated by hand (exact exponential steps of 1 us over
// the pulse's piecewise-linear shape), at the log's instants.
Eigen::VectorXd first_order_lag(const test::TorquePulse& pulse, double gain, const Eigen::VectorXd& time) {
  Eigen::VectorXd out(time.size());
  const double h = 1e-6, a = std::exp(-gain * h);
  double r = 0, t = 0;
  for (Eigen::Index k = 0; k < time.size(); ++k) {
    for (; t < time(k) - 0.5 * h; t += h) r = a * r + (1 - a) * pulse.at(t + 0.5 * h);
    out(k) = r;
  }
  return out;
}

template <class Model>
void residual_is_the_lagged_external_torque(const Eigen::VectorXd& phi, const test::TorquePulse& pulse, double gain) {
  const robot::ModelHandle& model = robot::compiled_model<Model>();
  const io::Log log = exact_log<Model>(phi, pulse, 3.0);
  const Eigen::VectorXd expected = first_order_lag(pulse, gain, log.time);
  // Both forms of the integral of Mdot qd (momentum_observer.hpp).
  for (const auto rate : {observer::InertiaRate::difference, observer::InertiaRate::derivatives}) {
    const char* form = rate == observer::InertiaRate::difference ? "difference" : "derivatives";
    observer::MomentumObserverOptions options;
    options.default_gain = gain;
    options.inertia_rate = rate;
    observer::MomentumObserver obs(model, phi, options);
    const Eigen::MatrixXd r = observer::observe_log(obs, log);
    for (int j = 0; j < Model::nq; ++j) {
      const double worst =
          j == pulse.joint ? (r.col(j) - expected).cwiseAbs().maxCoeff() : r.col(j).cwiseAbs().maxCoeff();
      // The pulse's joint: the discrete filter's step against the continuous lag over the 2 ms
      // ramps (up to 0.2 % at K = 200); elsewhere the integration's error alone.
      const double bound = (j == pulse.joint ? 5e-3 : 2e-4) * std::abs(pulse.torque);
      EXPECT_LT(worst, bound) << Model::robot_name << " joint " << j + 1 << ", " << form;
    }
    // The residual reached the pulse (not a trivially small one).
    EXPECT_GT(r.col(pulse.joint).cwiseAbs().maxCoeff(), 0.9 * std::abs(pulse.torque)) << form;
  }
}

twin::TwinConfig crane_twin() {
  return twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Crane::nq);
}

TEST(MomentumObserver, ResidualIsTheExternalTorqueThroughAFirstOrderLagCrane) {
  const Eigen::VectorXd phi = twin::make_truth(robot::compiled_model<Crane>(), crane_twin()).phi;
  residual_is_the_lagged_external_torque<Crane>(phi, {1, 1.0, 0.5, 1.5}, 50);
  residual_is_the_lagged_external_torque<Crane>(phi, {5, 2.0, 0.3, -0.4}, 200);
}

TEST(MomentumObserver, ResidualIsTheExternalTorqueThroughAFirstOrderLagRx90) {
  const Eigen::VectorXd phi = twin::make_truth(robot::compiled_model<Rx>(), test::rx90_twin()).phi;
  residual_is_the_lagged_external_torque<Rx>(phi, {2, 1.0, 0.5, 40}, 50);
  residual_is_the_lagged_external_torque<Rx>(phi, {4, 2.0, 0.3, -5}, 100);
}

TEST(MomentumObserver, RefusesWrongSizesAndGains) {
  const robot::ModelHandle& model = robot::compiled_model<Rx>();
  EXPECT_THROW(observer::MomentumObserver(model, Eigen::VectorXd::Zero(3)), std::invalid_argument);
  observer::MomentumObserverOptions o;
  o.gain = Eigen::VectorXd::Constant(2, 50);
  EXPECT_THROW(observer::MomentumObserver(model, Eigen::VectorXd::Zero(Rx::np), o), std::invalid_argument);
  o.gain = Eigen::VectorXd::Constant(Rx::nq, -1);
  EXPECT_THROW(observer::MomentumObserver(model, Eigen::VectorXd::Zero(Rx::np), o), std::invalid_argument);
}

TEST(CollisionDetection, ThresholdsRoundTripThroughTheirFileAndBadFilesNameTheLine) {
  observer::ObserverThresholds t;
  t.center = Eigen::Vector3d(0.1, -0.2, 1.0 / 3);
  t.spread = Eigen::Vector3d(0.01, 0.02, 0.03);
  t.tail = t.spread * 4.8;
  t.peak = Eigen::Vector3d(0.05, 0.1, 0.2);
  t.threshold = t.tail.cwiseMax(1.25 * t.peak);
  t.peak_margin = 1.25;
  t.false_alarms_per_hour = 0.5;
  const std::vector<std::string> joints{"a", "b", "c"};
  const Eigen::Vector3d gain(50, 40, 30);
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "observer_thresholds_test.yaml";
  std::ofstream(file) << observer::thresholds_yaml(t, joints, "arm", "full", gain, "quiet.csv");
  const observer::ThresholdsFile back = observer::read_thresholds_yaml(file.string(), joints);
  EXPECT_EQ(back.thresholds.center, t.center);  // numbers in their shortest round-trip form
  EXPECT_EQ(back.thresholds.threshold, t.threshold);
  EXPECT_EQ(back.gain, gain);
  EXPECT_EQ(back.robot, "arm");
  EXPECT_THROW(observer::read_thresholds_yaml(file.string(), {"a", "b", "x"}), DataError);  // other joints
  // A threshold that is no number: an error at its line, naming the file.
  std::string text = observer::thresholds_yaml(t, joints, "arm", "full", gain, "quiet.csv");
  const std::size_t at = text.find("threshold: [");
  text.replace(at, std::string("threshold: [").size(), "threshold: [x, ");
  const int line = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 1;
  std::ofstream(file) << text;
  try {
    observer::read_thresholds_yaml(file.string(), joints);
    ADD_FAILURE() << "a bad threshold was read";
  } catch (const DataError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
}

TEST(CollisionDetection, SpansCloseTogetherOnAJointAreOneEvent) {
  // r on joint 2 crosses its band at 1.00-1.01 s, again 50 ms later (1.06-1.07 s: the same event)
  // and 200 ms after that (1.27 s: another); joint 1 crosses at 1.065 s (its own event).
  const int rows = 2000;
  Eigen::VectorXd time = Eigen::VectorXd::LinSpaced(rows, 0, (rows - 1) * 0.001);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(rows, 2);
  for (int k = 1000; k <= 1010; ++k) r(k, 1) = 2;
  for (int k = 1060; k <= 1070; ++k) r(k, 1) = -3;
  r(1270, 1) = 2.5;
  r(1065, 0) = 5;
  observer::ObserverThresholds t;
  t.center = Eigen::Vector2d::Zero();
  t.threshold = Eigen::Vector2d::Ones();
  const auto events = observer::collision_events(time, r, t);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].joint, 1);
  EXPECT_DOUBLE_EQ(events[0].start, time(1000));
  EXPECT_DOUBLE_EQ(events[0].end, time(1070));
  EXPECT_DOUBLE_EQ(events[0].peak, -3);
  EXPECT_DOUBLE_EQ(events[0].peak_time, time(1060));
  EXPECT_EQ(events[1].joint, 0);
  EXPECT_DOUBLE_EQ(events[1].start, time(1065));
  EXPECT_EQ(events[2].joint, 1);
  EXPECT_DOUBLE_EQ(events[2].start, time(1270));
  EXPECT_EQ(observer::collision_events(time, r, t, 0.0).size(), 4u);  // no merging: every span
}

// ---- Detection on the independent arm ------------------------------------------------------

struct Detection {
  observer::ObserverThresholds thresholds;
  std::vector<observer::CollisionEvent> quiet, contact;
};

// Thresholds from `calibration` (no contact), then the events of `quiet` (no contact) and of
// `contact` (the pulse), with the model's parameters off by 2 % (an identification's error).
template <class Model>
Detection detect(const Eigen::VectorXd& truth, const std::vector<io::Log>& calibration, const io::Log& quiet,
                 const io::Log& contact) {
  test::Random rng(5);
  Eigen::VectorXd phi = truth;
  for (Eigen::Index i = 0; i < phi.size(); ++i) phi(i) *= 1 + 0.02 * rng.uniform(-1, 1);
  observer::MomentumObserver obs(robot::compiled_model<Model>(), phi);
  std::vector<Eigen::MatrixXd> residuals;
  std::vector<Eigen::VectorXd> times;
  for (const auto& log : calibration) {
    residuals.push_back(observer::observe_log(obs, log));
    times.push_back(log.time);
  }
  Detection d;
  d.thresholds = observer::observer_thresholds(residuals, times, obs.gain());
  d.quiet = observer::collision_events(quiet.time, observer::observe_log(obs, quiet), d.thresholds);
  d.contact = observer::collision_events(contact.time, observer::observe_log(obs, contact), d.thresholds);
  return d;
}

void expect_detected(const Detection& d, const test::TorquePulse& pulse, const std::string& robot) {
  EXPECT_TRUE(d.quiet.empty()) << robot << ": " << d.quiet.size() << " alarms without contact, the first on joint "
                               << (d.quiet.empty() ? 0 : d.quiet[0].joint + 1) << " at "
                               << (d.quiet.empty() ? 0 : d.quiet[0].start) << " s";
  ASSERT_FALSE(d.contact.empty()) << robot << ": the contact was missed";
  const observer::CollisionEvent& first = d.contact.front();
  EXPECT_EQ(first.joint, pulse.joint) << robot;
  EXPECT_GE(first.start, pulse.start) << robot;
  EXPECT_LE(first.start, pulse.start + 0.010) << robot;
  EXPECT_NEAR(first.peak, pulse.torque, 0.25 * std::abs(pulse.torque)) << robot;
  for (const auto& e : d.contact)
    EXPECT_EQ(e.joint, pulse.joint) << robot << ": an alarm on joint " << e.joint + 1 << " at " << e.start << " s";
  std::cout << robot << ": thresholds";
  for (Eigen::Index j = 0; j < d.thresholds.threshold.size(); ++j) std::cout << " " << d.thresholds.threshold(j);
  std::cout << " (" << d.thresholds.windows << " windows, the tail band's alarms on calibration "
            << d.thresholds.tail_alarms << "), detected " << 1000 * (first.start - pulse.start)
            << " ms after the pulse, peak " << first.peak << "\n";
}

TEST(CollisionDetection, ACraneContactIsFoundOnItsJointWithin10ms) {
  const twin::TwinConfig c = crane_twin();
  static const auto design =
      trajectory::TrajectoryDesign::read(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/trajectories.yaml",
                                         std::vector<JointInfo>(Crane::joints.begin(), Crane::joints.end()));
  test::IndependentArmOptions o;
  o.coulomb = Eigen::VectorXd::Constant(Crane::nq, 0.03);
  const auto run = [&](const std::string& name, unsigned seed, std::vector<test::TorquePulse> pulses) {
    test::IndependentArmOptions r = o;
    r.seed = seed;
    r.pulses = std::move(pulses);
    return test::run_independent_arm<Crane>(c, trajectory::sample(design.build(name), 0.001), r);
  };
  const test::TorquePulse pulse{5, 6.0, 0.2, 2.0};
  const Eigen::VectorXd truth = twin::make_truth(robot::compiled_model<Crane>(), c).phi;
  const Detection d =
      detect<Crane>(truth, {run("V01", 11, {}), run("AG02", 12, {})}, run("V02", 13, {}), run("V03", 14, {pulse}));
  expect_detected(d, pulse, "crane_x7");
}

TEST(CollisionDetection, AnRx90ContactIsFoundOnItsJointWithin10ms) {
  const twin::TwinConfig c = test::rx90_twin();
  test::IndependentArmOptions o;
  o.coulomb = Eigen::VectorXd::Constant(Rx::nq, 1.0);
  const auto run = [&](unsigned seed, std::vector<test::TorquePulse> pulses) {
    test::IndependentArmOptions r = o;
    r.seed = seed;
    r.pulses = std::move(pulses);
    return test::run_independent_arm<Rx>(c, test::rx90_reference("excite", 20, seed), r);
  };
  const test::TorquePulse pulse{2, 8.0, 0.2, -25.0};
  const Eigen::VectorXd truth = twin::make_truth(robot::compiled_model<Rx>(), c).phi;
  const Detection d = detect<Rx>(truth, {run(21, {}), run(22, {})}, run(23, {}), run(24, {pulse}));
  expect_detected(d, pulse, "rx90");
}

TEST(CollisionDetection, TheTwinsContactFromTwinYamlIsFoundOnItsJointWithin10ms) {
  // The twin at its own levels (robots/crane_x7/twin.yaml: noise, jitter, dropped samples), and a
  // contact an override file switches on.
  const std::string dir = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";
  const std::filesystem::path override_file = std::filesystem::temp_directory_path() / "observer_contact.yaml";
  std::ofstream(override_file) << "effects:\n  contact: {enabled: true, joint: 6, start: 6.0, duration: 0.2, "
                                  "torque: 2.0}\n";
  twin::TwinConfig with = twin::read_twin_config(dir + "/twin.yaml", Crane::nq, override_file);
  std::filesystem::remove(override_file);
  ASSERT_TRUE(with.effects.contact);
  EXPECT_EQ(with.effects.contact_joint, 6);
  twin::TwinConfig without = with;
  without.effects.contact = false;
  static const auto design = trajectory::TrajectoryDesign::read(
      dir + "/trajectories.yaml", std::vector<JointInfo>(Crane::joints.begin(), Crane::joints.end()));
  const auto run = [&](const twin::TwinConfig& c, const std::string& name, std::uint64_t seed) {
    twin::RunOptions o;
    o.robot = "crane_x7";
    o.seed = seed;
    return twin::ClosedLoopTwin(robot::compiled_model<Crane>(), c).run(design.build(name), o);
  };
  const Eigen::VectorXd truth = twin::make_truth(robot::compiled_model<Crane>(), without).phi;
  const Detection d = detect<Crane>(truth, {run(without, "V01", 31), run(without, "AG02", 32)}, run(without, "V02", 33),
                                    run(with, "V03", 34));
  expect_detected(d, {5, 6.0, 0.2, 2.0}, "crane_x7 twin");
}

}  // namespace
