// The 1 kHz controller end to end (hardware_rig.hpp): tracking is checked against an independent
// reference, the twin's own closed loop of the same trajectory without the bus
// (twin/simulator.hpp), and the twin's tracking-error bound; bus faults (CRC bursts, timeouts, a
// lost servo, a hardware error, a non-finite command) must end in a safe state read back from
// the virtual servos' control tables, with a log that io::read_log accepts up to the stop.
#include <random>

#include <symoro/ur5.hpp>

#include "hardware_rig.hpp"
#include "symoro/robot/compiled_model.hpp"

namespace symoro::hardware {
namespace {

TEST_F(HardwareControl, ConfigErrorsNameFileAndLine) {
  const auto bad = dir_ / "hardware.yaml";
  std::ifstream in(kRobot / "hardware.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto pos = text.find("id: 5, model: XM430-W350");
  ASSERT_NE(pos, std::string::npos);
  std::string broken = text;
  broken.replace(pos, 24, "id: 4, model: XM430-W350");
  std::ofstream(bad) << broken;
  try {
    read_hardware_config(bad, joints());
    FAIL() << "a duplicate ID was accepted";
  } catch (const DataError& e) {
    EXPECT_GT(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("servo ID 4 is used twice"), std::string::npos) << e.what();
  }
  broken = text;
  broken.replace(broken.find("model: XM540-W270, zero"), 17, "model: XM999-W999");
  std::ofstream(bad) << broken;
  EXPECT_THROW(read_hardware_config(bad, joints()), DataError);
}

TEST_F(HardwareControl, TracksFiveSecondsOverThePtyLikeTheTwin) {
  const trajectory::Trajectory traj = first_seconds("AG02", 5.0);
  ASSERT_GE(traj.duration(), 5.0);
  ASSERT_LE(traj.duration(), 12.0);
  // What the loop could control: a row is judged only when the 1 kHz loop ran undisturbed over
  // the settling time before it (5 / w of the slowest joint's error dynamics, K_P = w^2: a
  // disturbance has decayed to under 1 %). A stall of a loaded machine (a skipped deadline, a
  // failed sync read: the arm runs on held currents meanwhile) shows in the log as a gap in the
  // time stamps, since only fresh cycles write a row. The bounds below never change. A stall is
  // the host's (this test runs alone, RUN_SERIAL), and the process's first run stalls most (here
  // 1882-2548 of ~5600 rows judged against 3102-4560 for the second, also in CI): a run that
  // leaves fewer than half of its rows to judge is repeated, up to three runs; if none does, the
  // test fails, saying so.
  const double settle = 5 / gains_.kp.cwiseSqrt().minCoeff();
  std::unique_ptr<Rig> rig;
  io::Log log;
  std::vector<bool> judged;
  int judged_rows = 0;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    rig = std::make_unique<Rig>(twin_, hw_, traj);
    const std::string csv = (dir_ / ("AG02_" + std::to_string(attempt) + ".csv")).string();
    const ControlResult r = run(*rig, traj, csv, options());
    ASSERT_EQ(r.reason, StopReason::completed) << r.message;
    EXPECT_TRUE(r.torque_off_confirmed);
    rig->expect_safe();
    expect_log(r, csv);
    log = io::read_log(csv);
    EXPECT_EQ(r.stop_action, StopAction::hold) << r.at_stop;  // the end of a run is a stop too
    EXPECT_NEAR(r.held, hw_.safety.hold_time, 1e-9) << r.at_stop;
    const int expected = static_cast<int>(std::llround(traj.duration() / 0.001)) + 1;
    EXPECT_GE(log.samples(), expected * 90 / 100);  // cycles lost to a loaded machine are dropped rows
    EXPECT_GT(r.timing.cycles, expected);
    EXPECT_NEAR(r.timing.period_mean, 0.001, 0.0001);  // absolute deadlines: no drift
    judged.assign(log.samples(), false);
    double last_gap = -1e9;
    judged_rows = 0;
    for (int k = 1; k < log.samples(); ++k) {
      if (log.time(k) - log.time(k - 1) > 1.5e-3) last_gap = log.time(k);
      judged[k] = log.time(k) - last_gap >= settle;
      judged_rows += judged[k];
    }
    std::printf("run %d: rows judged: %d of %d (undisturbed for %.0f ms before; %lld failed reads, %lld skipped deadlines)\n", attempt,
                judged_rows, log.samples(), settle * 1e3, static_cast<long long>(r.timing.read_failures),
                static_cast<long long>(r.timing.skipped));
    if (judged_rows >= log.samples() / 2) break;
  }
  ASSERT_GE(judged_rows, log.samples() / 2) << "the machine stalled the loop too often, three runs in a row, to judge its tracking";

  // The reference: the twin's own closed loop of the same trajectory, no bus.
  const twin::ClosedLoopTwin sim(symoro::robot::compiled_model<Model>(), twin_);
  twin::RunOptions ro;
  ro.robot = "crane_x7";
  twin::RunStats st;
  const io::Log ref = sim.run(traj, ro, &st);

  // Joint paths agree sample by sample (reference interpolated at the bus run's times).
  Eigen::VectorXd worst_joint = Eigen::VectorXd::Zero(Model::nq), max_error = Eigen::VectorXd::Zero(Model::nq);
  for (int k = 0; k < log.samples(); ++k) {
    if (!judged[k]) continue;
    const double t = log.time(k);
    const double x = std::clamp(t / 0.001, 0.0, static_cast<double>(ref.samples() - 1));
    const int i = std::min(static_cast<int>(x), ref.samples() - 2);
    const double w = x - i;
    for (int j = 0; j < Model::nq; ++j) {
      // Compare tracking errors (q_ref - q) at the same instant: insensitive to the row's time
      // stamp jitter along the reference.
      const double e_bus = log.q_ref(k, j) - log.q(k, j);
      const double e_ref = (1 - w) * (ref.q_ref(i, j) - ref.q(i, j)) + w * (ref.q_ref(i + 1, j) - ref.q(i + 1, j));
      worst_joint(j) = std::max(worst_joint(j), std::abs(e_bus - e_ref));
      max_error(j) = std::max(max_error(j), std::abs(e_bus));
    }
  }
  std::printf("bus run: max |q_ref - q| per joint (deg) over the judged rows:");
    for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", max_error(j) * kDeg);
  std::printf("\ntwin run (no bus):                     ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", st.max_error(j) * kDeg);
  std::printf("\nmax |e_bus - e_twin| per joint (deg):  ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", worst_joint(j) * kDeg);
  std::printf("\n");
  // The tracking-error bound of the twin's loop (with its 0.9 ms delay: the bus is faster here).
  const Eigen::VectorXd sup_w = twin::unmodeled_torque(twin_, traj, [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
    Eigen::Matrix<double, Model::nq, 1> tau;
    Model::inverse_dynamics(Eigen::Matrix<double, Model::nq, 1>(q), Eigen::Matrix<double, Model::nq, 1>(qd),
                            Eigen::Matrix<double, Model::nq, 1>(qdd), rig->backend->truth().phi, tau);
    return Eigen::VectorXd(tau);
  });
  const Eigen::VectorXd bound = twin::tracking_error_bound(twin_, sup_w);
  std::printf("tracking-error bound (deg):            ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", bound(j) * kDeg);
  std::printf("\n");
  for (int j = 0; j < Model::nq; ++j) {
    const double lsb = 2 * 3.14159265358979323846 / 4096;
    // The bound holds for the twin's fixed timing; the bus's own timing differs a little.
    EXPECT_LE(max_error(j), 2 * bound(j) + 2 * lsb) << "joint " << j + 1 << " bound " << bound(j) * kDeg << " deg";
    // Same loop, same plant: the errors agree to a fraction of the error itself plus a few
    // encoder steps (the bus's delay and timing differ from the twin's fixed 0.9 ms).
    EXPECT_LE(worst_joint(j), 0.5 * st.max_error(j) + 4 * lsb) << "joint " << j + 1;
  }
}

TEST_F(HardwareControl, ShortCrcBurstIsRiddenThrough) {
  const trajectory::Trajectory traj = first_seconds("AG02", 1.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 1.0;
  const std::string csv = (dir_ / "crc_short.csv").string();
  const ControlResult r = run(rig, traj, csv, o, 0.9, [](Rig& g) { g.virt.corrupt_replies(3); });
  EXPECT_EQ(r.reason, StopReason::completed) << r.message;
  EXPECT_GT(r.timing.bus.crc_errors, 0u);
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, LongCrcBurstTripsTheWatchdog) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "crc_long.csv").string();
  const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig& g) { g.virt.corrupt_replies(1'000'000); });
  EXPECT_EQ(r.reason, StopReason::watchdog) << r.message;
  EXPECT_GE(r.timing.max_stale, kWatchdog);
  EXPECT_EQ(r.stop_action, StopAction::torque_off);  // no state to hold with
  EXPECT_NE(r.at_stop.find("state is lost"), std::string::npos) << r.at_stop;
  EXPECT_GT(r.trajectory_time, 0.2);
  EXPECT_LT(r.trajectory_time, 1.5);
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, TimeoutsTripTheWatchdog) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "timeouts.csv").string();
  const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig& g) { g.virt.drop_replies(1'000'000); });
  EXPECT_EQ(r.reason, StopReason::watchdog) << r.message;
  EXPECT_GT(r.timing.bus.timeouts, 0u);
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, LostServoStopsAndIsNamed) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "lost.csv").string();
  const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig& g) { g.virt.set_dead(5, true); });
  EXPECT_EQ(r.reason, StopReason::servo_lost) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::torque_off);
  EXPECT_NE(r.message.find("servo ID 5 (joint 4 elbow)"), std::string::npos) << r.message;
  EXPECT_FALSE(r.torque_off_confirmed);  // the dead servo cannot confirm
  rig.expect_safe(5);                     // every other servo is off
  expect_log(r, csv);
  // Once it answers again, a safe stop reaches it too.
  rig.virt.set_dead(5, false);
  EXPECT_TRUE(safe_stop(rig.bus, hw_));
  rig.expect_safe();
}

TEST_F(HardwareControl, HardwareErrorStopsWithItsStatus) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "alert.csv").string();
  const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig& g) { g.virt.set_hardware_error(7, xs::hardware_error::kOverload); });
  EXPECT_EQ(r.reason, StopReason::hardware_error) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::torque_off);
  EXPECT_NE(r.message.find("servo ID 7"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("overload"), std::string::npos) << r.message;
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, ANonFiniteCommandStopsAndIsNamed) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  // A feedforward model that returns NaN on joint 3 from its 1500th call on (the approach and
  // pre-roll call it too): never a silent zero or a saturated command.
  // (From trajectory time 0.5 s on: before torque on, the check of every reference must pass.)
  auto broken = std::make_shared<std::atomic<bool>>(false);
  o.feedforward = [broken](const Eigen::VectorXd& q, const Eigen::VectorXd&, const Eigen::VectorXd&, Eigen::VectorXd& tau) {
    tau = Eigen::VectorXd::Zero(q.size());
    if (broken->load()) tau(2) = std::numeric_limits<double>::quiet_NaN();
  };
  const std::string csv = (dir_ / "nan.csv").string();
  const ControlResult r = run(rig, traj, csv, o, 0.5, [broken](Rig&) { broken->store(true); });
  EXPECT_EQ(r.reason, StopReason::invalid_command) << r.message;
  // Held on PD alone: the feedforward that failed is not asked for gravity.
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_NE(r.at_stop.find("(PD;"), std::string::npos) << r.at_stop;
  EXPECT_NE(r.message.find("joint 3"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("nan"), std::string::npos) << r.message;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

// dynid control's feedforward for any robot is the handle's (one indirect call of the robot
// library's kernel): the same torques and mass matrix as the generated model's inline call, bit
// for bit, on the identified models of two robots; a vector of the wrong size is refused.
template <class Identified>
void expect_handle_feedforward_equals_inline(std::uint32_t seed) {
  const robot::ModelHandle& handle = robot::compiled_model<Identified>();
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  Eigen::VectorXd phi(Identified::np), q(Identified::nq), qd(Identified::nq), qdd(Identified::nq);
  for (auto* v : {&phi, &q, &qd, &qdd})
    for (Eigen::Index i = 0; i < v->size(); ++i) (*v)(i) = u(gen);
  const auto ff_inline = model_feedforward<Identified>(phi), ff_handle = model_feedforward(handle, phi);
  const auto m_inline = model_inertia<Identified>(phi), m_handle = model_inertia(handle, phi);
  Eigen::VectorXd a, b;
  Eigen::MatrixXd Ma, Mb;
  for (int k = 0; k < 20; ++k) {
    ff_inline(q, qd, qdd, a), ff_handle(q, qd, qdd, b);
    m_inline(q, Ma), m_handle(q, Mb);
    ASSERT_EQ(a.size(), Identified::nq);
    EXPECT_EQ(a, b);
    EXPECT_EQ(Ma, Mb);
    q = q.unaryExpr([&](double x) { return x + u(gen); });
  }
  EXPECT_THROW(model_feedforward(handle, Eigen::VectorXd::Zero(Identified::np + 1)), std::invalid_argument);
  EXPECT_THROW(model_inertia(handle, Eigen::VectorXd::Zero(1)), std::invalid_argument);
}

TEST(ModelFeedforward, ThroughTheHandleEqualsTheInlineCall) {
  expect_handle_feedforward_equals_inline<crane_x7::IdentifiedModel>(3);
  expect_handle_feedforward_equals_inline<ur5::IdentifiedModel>(4);
}

TEST_F(HardwareControl, ModelFeedforwardFromAStudysParameters) {
  using Identified = crane_x7::IdentifiedModel;
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  // A report/parameters.yaml holding the twin's true parameters in the identified model.
  const Eigen::VectorXd phi = Identified::from_parent(rig.backend->truth().phi);
  std::string yaml = "robot: \"crane_x7\"\naccepted: true\nparameters:\n";
  std::vector<std::string> names;
  for (int i = 0; i < Identified::np; ++i) {
    names.emplace_back(Identified::parameters[i].name);
    yaml += "  - {name: \"" + names.back() + "\", unit: \"-\", value: " + io::number_text(phi(i)) + "}\n";
  }
  const auto file = dir_ / "parameters.yaml";
  std::ofstream(file) << yaml;
  const Eigen::VectorXd read = io::read_parameters_yaml(file.string(), names);
  EXPECT_EQ(read, phi);
  // A missing parameter is named with the file.
  std::ofstream(dir_ / "short.yaml") << yaml.substr(0, yaml.rfind("  - {"));
  try {
    io::read_parameters_yaml((dir_ / "short.yaml").string(), names);
    FAIL() << "a missing parameter was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("short.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(names.back()), std::string::npos) << e.what();
  }

  ControlOptions o = options();
  o.seconds = 2.0;
  o.feedforward = model_feedforward<Identified>(read);
  o.inertia = model_inertia<Identified>(read);
  const ControlResult r = run(rig, traj, (dir_ / "ff.csv").string(), o);
  ASSERT_EQ(r.reason, StopReason::completed) << r.message;
  // The end of the run cannot be the feedforward's doing: the hold adds its gravity.
  EXPECT_NE(r.at_stop.find("PD + the model's gravity"), std::string::npos) << r.at_stop;
  rig.expect_safe();
  // FF+PD alone (the twin's loop) leaves gravity to the PD; the model feedforward cancels it.
  const twin::ClosedLoopTwin sim(symoro::robot::compiled_model<Model>(), twin_);
  twin::RunOptions ro;
  ro.robot = "crane_x7";
  twin::RunStats st;
  sim.run(traj, ro, &st);
  std::printf("max |q_ref - q| (deg), model feedforward over the bus vs FF+PD alone (twin):\n");
  for (int j = 0; j < Model::nq; ++j) std::printf("  joint %d: %.3f vs %.3f\n", j + 1, r.max_error(j) * kDeg, st.max_error(j) * kDeg);
  EXPECT_LT(r.max_error(1), 0.5 * st.max_error(1));  // shoulder tilt
  EXPECT_LT(r.max_error(3), 0.5 * st.max_error(3));  // elbow
}

// Parameters with `accepted: true` but one value edited never reach the servos: MX2 = 50 asks
// joint 2 for far more torque than its limit, ZZR2 = -100 makes M(q) indefinite. The run stops
// in its setup, torque never on, and the refusal names the joint or the matrix.
TEST_F(HardwareControl, AnEditedModelIsRefusedBeforeTorqueOn) {
  using Identified = crane_x7::IdentifiedModel;
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  struct Case {
    const char* name;
    double value;
    const char* says;
  };
  for (const Case& c : {Case{"MX2", 50.0, "joint 2 "}, Case{"ZZR2", -100.0, "is not positive definite"}}) {
    Rig rig(twin_, hw_, traj);
    Eigen::VectorXd phi = Identified::from_parent(rig.backend->truth().phi);
    int i = 0;
    while (std::string(Identified::parameters[i].name) != c.name) ++i;
    phi(i) = c.value;
    ControlOptions o = options();
    o.seconds = 2.0;
    o.feedforward = model_feedforward<Identified>(phi);
    o.inertia = model_inertia<Identified>(phi);
    const std::string csv = (dir_ / fmt::format("edited_{}.csv", c.name)).string();
    const ControlResult r = run(rig, traj, csv, o);
    EXPECT_EQ(r.reason, StopReason::setup_failed) << c.name << ": " << r.message;
    EXPECT_NE(r.message.find("the model feedforward is refused before torque on"), std::string::npos) << r.message;
    EXPECT_NE(r.message.find(c.says), std::string::npos) << r.message;
    EXPECT_EQ(r.at_stop, "torque off (it had not been turned on)");
    EXPECT_EQ(r.rows, 0);
    rig.expect_safe();
  }
}

// A limit stop may be the feedforward's doing: the hold then uses PD alone, never the model's
// gravity (which, from a wrong model, held the arm 253 deg off the stop pose).
TEST_F(HardwareControl, ALimitStopHoldsWithoutTheModelsGravity) {
  using Identified = crane_x7::IdentifiedModel;
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  const Eigen::VectorXd phi = Identified::from_parent(rig.backend->truth().phi);
  ControlOptions o = options();
  o.seconds = 2.0;
  o.feedforward = model_feedforward<Identified>(phi);
  o.inertia = model_inertia<Identified>(phi);
  // Joint j's velocity limit at half the reference's peak: the arm trips it mid-run.
  Eigen::VectorXd q(Model::nq), v(Model::nq), a(Model::nq), peak = Eigen::VectorXd::Zero(Model::nq);
  for (double t = 0; t < 2.0; t += 0.01) {
    traj.evaluate(t, q, v, a);
    peak = peak.cwiseMax(v.cwiseAbs());
  }
  int j = 0;
  peak.maxCoeff(&j);
  std::vector<JointInfo> js = joints();
  js[j].velocity = 0.5 * peak(j) / hw_.safety.velocity_factor;
  const ControlResult r = run(rig, traj, (dir_ / "limit_ff.csv").string(), o, -1, {}, js);
  EXPECT_EQ(r.reason, StopReason::velocity_limit) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_NE(r.at_stop.find("(PD (a velocity_limit stop may come from the model feedforward)"), std::string::npos) << r.at_stop;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
}

}  // namespace
}  // namespace symoro::hardware
