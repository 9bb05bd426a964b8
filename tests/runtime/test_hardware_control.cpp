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
  // No value switches a limit off: each is bounded, and the error names the file's line.
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"velocity_factor: 1.0", "velocity_factor: 100"},
                                                        {"position_tolerance: 0.05", "position_tolerance: 1e9"},
                                                        {"current_trip_factor: 1.5", "current_trip_factor: 0.5"},
                                                        {"approach_speed: 0.3", "approach_speed: 5"},
                                                        {"pre_roll: 0.5", "pre_roll: -1"},
                                                        {"hold_time: 2.0", "hold_time: 1000"},
                                                        {"zero: 2048", "zero: 99999"}}) {
    broken = text;
    const auto at = broken.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    broken.replace(at, from.size(), to);
    std::ofstream(bad) << broken;
    const std::string key = from.substr(0, from.find(':'));
    try {
      read_hardware_config(bad, joints());
      ADD_FAILURE() << to << " was accepted";
    } catch (const DataError& e) {
      EXPECT_GT(e.line(), 0) << e.what();
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  // The servos' bus watchdog: 20 ms units up to 127, or 0; the file's 0.1 s is 5 units.
  EXPECT_NEAR(read_hardware_config(kRobot / "hardware.yaml", joints()).safety.bus_watchdog, 0.1, 1e-12);
  for (const char* value : {"3", "-0.1", "nan"}) {
    broken = text;
    broken.replace(broken.find("bus_watchdog: 0.1"), 17, std::string("bus_watchdog: ") + value);
    std::ofstream(bad) << broken;
    try {
      read_hardware_config(bad, joints());
      ADD_FAILURE() << "bus_watchdog " << value << " was accepted";
    } catch (const DataError& e) {
      EXPECT_GT(e.line(), 0);
      EXPECT_NE(std::string(e.what()).find("safety.bus_watchdog"), std::string::npos) << e.what();
    }
  }
}

TEST_F(HardwareControl, TracksFiveSecondsOverThePtyLikeTheTwin) {
  const trajectory::Trajectory traj = first_seconds("AG02", 5.0);
  ASSERT_GE(traj.duration(), 5.0);
  ASSERT_LE(traj.duration(), 12.0);
  // The loop and the emulated arm run on the rig's stepped clock, unpaced: every cycle happens
  // at its deadline on the arm's time however long the host takes, so the machine's load cannot
  // change what is judged here (real-time behaviour: bench_control_loop). The bus is still the
  // real driver over a pseudo-terminal, made patient: a transaction waits up to 1 s of real time
  // for the emulated servos' thread. Before each step, a ping answered proves the arm took the
  // cycle's command (sent before it): the rows are then the same on any machine.
  Rig rig(twin_, hw_, traj, RigClock::unpaced);
  const std::uint8_t first_id = hw_.ids().front();
  int unanswered = 0;
  rig.clock.set_before_step([&rig, &unanswered, first_id] {
    for (int attempt = 0; attempt < 5; ++attempt)
      if (rig.bus.ping(first_id, std::chrono::steady_clock::now() + std::chrono::seconds(1)).has_data()) return;
    ++unanswered;
  });
  dynamixel::BusOptions patient = rig.bus.options();
  patient.margin = std::chrono::milliseconds(1000);
  patient.retries = 3;
  rig.bus.set_options(patient);
  const std::string csv = (dir_ / "AG02.csv").string();
  const ControlResult r = run(rig, traj, csv, options());
  ASSERT_EQ(r.reason, StopReason::completed) << r.message;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
  const io::Log log = io::read_log(csv);
  EXPECT_EQ(r.stop_action, StopAction::hold) << r.at_stop;  // the end of a run is a stop too
  EXPECT_NEAR(r.held, hw_.safety.hold_time, 1e-9) << r.at_stop;
  // On time every cycle: one row per period from t = 0 to the end, none lost.
  EXPECT_EQ(unanswered, 0);
  EXPECT_EQ(r.timing.overruns, 0);
  EXPECT_EQ(r.timing.read_failures, 0) << "a transaction waited more than 1 s for the emulated servos";
  const int expected = static_cast<int>(std::llround(traj.duration() / 0.001)) + 1;
  ASSERT_EQ(log.samples(), expected);
  for (int k = 0; k < log.samples(); ++k) ASSERT_NEAR(log.time(k), k * 0.001, 1e-9) << "row " << k;

  // The reference: the twin's own closed loop of the same trajectory, no bus, with the stepped
  // loop's timing: the state read at t_k, the command in effect from t_k (no bus delay), the
  // same pre-roll.
  twin::TwinConfig reference = twin_;
  reference.controller.communication_delay = 0;
  const twin::ClosedLoopTwin sim(symoro::robot::compiled_model<Model>(), reference);
  twin::RunOptions ro;
  ro.robot = "crane_x7";
  ro.pre_roll = hw_.safety.pre_roll;
  twin::RunStats st;
  const io::Log ref = sim.run(traj, ro, &st);
  ASSERT_EQ(ref.samples(), log.samples());
  const double lsb = 2 * 3.14159265358979323846 / 4096;

  // Same controller, same plant, same timing: the bus run's rows are the twin's, up to what the
  // two paths round differently (a servo's current in its units after the direction, the plant
  // integrated to a clock counted in nanoseconds: its steps differ by 1e-16 s). Measured: at
  // most 1 encoder step on every joint, 0.2-0.55 steps RMS. At this scale the quantized loop is
  // chaotic (a 0.2 ms delay moves the twin's own rows as much), so 2 steps is the tolerance; a
  // wrong direction, zero, unit or torque constant moves the arm by degrees.
  Eigen::VectorXd q_diff = Eigen::VectorXd::Zero(Model::nq), tau_diff = Eigen::VectorXd::Zero(Model::nq);
  Eigen::VectorXd max_error = Eigen::VectorXd::Zero(Model::nq);
  for (int k = 0; k < log.samples(); ++k)
    for (int j = 0; j < Model::nq; ++j) {
      EXPECT_NEAR(log.q_ref(k, j), ref.q_ref(k, j), 1e-12) << "row " << k << " joint " << j + 1;
      q_diff(j) = std::max(q_diff(j), std::abs(log.q(k, j) - ref.q(k, j)));
      tau_diff(j) = std::max(tau_diff(j), std::abs(log.tau(k, j) - ref.tau(k, j)));
      max_error(j) = std::max(max_error(j), std::abs(log.q_ref(k, j) - log.q(k, j)));
    }
  std::printf("bus run: max |q_ref - q| per joint (deg):");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", max_error(j) * kDeg);
  std::printf("\ntwin run (no bus):                       ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", st.max_error(j) * kDeg);
  std::printf("\nmax |q_bus - q_twin| (encoder steps):     ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.1f", q_diff(j) / lsb);
  std::printf("\nmax |tau_bus - tau_twin| (N m):            ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.4f", tau_diff(j));
  std::printf("\n");
  // The tracking-error bound of that loop (twin/tracking_bound.hpp: the controller, its timing,
  // the plant's unmodelled torque along the trajectory).
  const Eigen::VectorXd sup_w = twin::unmodeled_torque(
      reference, traj, [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
        Eigen::Matrix<double, Model::nq, 1> tau;
        Model::inverse_dynamics(Eigen::Matrix<double, Model::nq, 1>(q), Eigen::Matrix<double, Model::nq, 1>(qd),
                                Eigen::Matrix<double, Model::nq, 1>(qdd), rig.backend->truth().phi, tau);
        return Eigen::VectorXd(tau);
      });
  const Eigen::VectorXd bound = twin::tracking_error_bound(reference, sup_w);
  std::printf("tracking-error bound (deg):              ");
  for (int j = 0; j < Model::nq; ++j) std::printf(" %.3f", bound(j) * kDeg);
  std::printf("\n");
  for (int j = 0; j < Model::nq; ++j) {
    EXPECT_LE(max_error(j), bound(j) + 2 * lsb) << "joint " << j + 1 << " bound " << bound(j) * kDeg << " deg";
    EXPECT_LE(q_diff(j), 2 * lsb) << "joint " << j + 1;
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
  rig.expect_safe(5);                    // every other servo is off
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
  const ControlResult r =
      run(rig, traj, csv, o, 0.5, [](Rig& g) { g.virt.set_hardware_error(7, xs::hardware_error::kOverload); });
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
  o.feedforward = [broken](const Eigen::VectorXd& q, const Eigen::VectorXd&, const Eigen::VectorXd&,
                           Eigen::VectorXd& tau) {
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
  for (int j = 0; j < Model::nq; ++j)
    std::printf("  joint %d: %.3f vs %.3f\n", j + 1, r.max_error(j) * kDeg, st.max_error(j) * kDeg);
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
  EXPECT_NE(r.at_stop.find("(PD (a velocity_limit stop may come from the model feedforward)"), std::string::npos)
      << r.at_stop;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
}

}  // namespace
}  // namespace symoro::hardware
