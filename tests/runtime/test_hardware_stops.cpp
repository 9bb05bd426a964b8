// The controller's stops (hardware_rig.hpp): position, velocity and current limits (also while a
// servo is silent), SIGINT, and what the arm does at a stop (hardware.yaml safety.at_stop: hold
// the stop pose, then torque off; or torque off at once), each read back from the emulated servos.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "hardware_rig.hpp"

namespace symoro::hardware {
namespace {

// The robot's joints with joint j's position limit moved to where the reference crosses it
// at trajectory time `t` (beyond the safety tolerance): the arm reaches it during the run.
std::vector<JointInfo> limit_crossed(const trajectory::Trajectory& traj, int j, double t, double tolerance) {
  std::vector<JointInfo> js = joints();
  Eigen::VectorXd q0(Model::nq), q1(Model::nq), v(Model::nq), a(Model::nq);
  traj.evaluate(0, q0, v, a);
  traj.evaluate(t, q1, v, a);
  if (q1(j) > q0(j))
    js[j].upper = q1(j) - tolerance;
  else
    js[j].lower = q1(j) + tolerance;
  return js;
}

// The joint that moves most over the first `t` seconds.
int moving_joint(const trajectory::Trajectory& traj, double t) {
  Eigen::VectorXd q0(Model::nq), q1(Model::nq), v(Model::nq), a(Model::nq);
  traj.evaluate(0, q0, v, a);
  traj.evaluate(t, q1, v, a);
  int j = 0;
  (q1 - q0).cwiseAbs().maxCoeff(&j);
  return j;
}

TEST_F(HardwareControl, PositionLimitStops) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  const int j = moving_joint(traj, 1.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "position.csv").string();
  const ControlResult r = run(rig, traj, csv, o, -1, {}, limit_crossed(traj, j, 0.8, hw_.safety.position_tolerance));
  EXPECT_EQ(r.reason, StopReason::position_limit) << r.message;
  EXPECT_NE(r.message.find(fmt::format("joint {} ", j + 1)), std::string::npos) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_GT(r.trajectory_time, 0.5);  // the arm follows the reference with a lag: after 0.8 s
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, VelocityLimitStops) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  const int j = moving_joint(traj, 1.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  std::vector<JointInfo> js = joints();
  double peak = 0;  // the reference's fastest over the run
  Eigen::VectorXd q(Model::nq), v(Model::nq), a(Model::nq);
  for (double t = 0; t < 2.0; t += 0.01) {
    traj.evaluate(t, q, v, a);
    peak = std::max(peak, std::abs(v(j)));
  }
  js[j].velocity = 0.5 * peak / hw_.safety.velocity_factor;
  const std::string csv = (dir_ / "velocity.csv").string();
  const ControlResult r = run(rig, traj, csv, o, -1, {}, js);
  EXPECT_EQ(r.reason, StopReason::velocity_limit) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_NE(r.message.find(fmt::format("joint {} ", j + 1)), std::string::npos) << r.message;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, CurrentLimitStops) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  // Trip at half of joint 1's current limit; the other joints' limits (and trip levels) raised
  // fourfold, so that only joint 1 can trip (the shoulder holds gravity at over half of its own).
  hw_.safety.current_trip_factor = 0.5;
  std::vector<JointInfo> js = joints();
  for (int j = 1; j < Model::nq; ++j) {
    hw_.joints[j].current_limit *= 4;
    js[j].effort = 1e3;  // the limit is min(current limit, effort / kt): the current limit's
  }
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  // From trajectory time 0.5 s a feedforward asks joint 1 for far more than its current limit:
  // the command saturates at the limit, and the present current passes the trip level.
  std::atomic<double> timeline{-1e9};
  auto* clock = &timeline;
  o.feedforward = [clock](const Eigen::VectorXd& q, const Eigen::VectorXd&, const Eigen::VectorXd&,
                          Eigen::VectorXd& tau) {
    tau = Eigen::VectorXd::Zero(q.size());
    if (clock->load() >= 0.5) tau(0) = 100;
  };
  const std::string csv = (dir_ / "current.csv").string();
  o.timeline = &timeline;
  o.clock = &rig.clock;
  const ControlResult r = run_control(rig.bus, hw_, js, gains_, traj, csv, o);
  EXPECT_EQ(r.reason, StopReason::current_limit) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::torque_off);  // a servo past its current is not obeying
  EXPECT_NE(r.message.find("joint 1 "), std::string::npos) << r.message;
  EXPECT_GT(r.trajectory_time, 0.45);
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

TEST_F(HardwareControl, ALimitIsCheckedWhileAServoDoesNotAnswer) {
  // Servo 5 (joint 4) stops answering at trajectory time 0.3 s; the watchdog is long (2 s), so
  // the stale state lasts while the moving joint crosses its limit at 0.8 s: the limit stops
  // the arm, not the watchdog.
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  int j = moving_joint(traj, 1.0);
  ASSERT_NE(j, 3) << "the moving joint must not be the silent one";
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  o.watchdog_cycles = 2000;
  const std::string csv = (dir_ / "stale_limit.csv").string();
  const ControlResult r = run(
      rig, traj, csv, o, 0.3, [](Rig& g) { g.virt.set_dead(5, true); },
      limit_crossed(traj, j, 0.8, hw_.safety.position_tolerance));
  EXPECT_EQ(r.reason, StopReason::position_limit) << r.message;
  EXPECT_GT(r.timing.max_stale, 100);  // the limit was found while joint 4's state was stale
  rig.expect_safe(5);
  expect_log(r, csv);
}

TEST_F(HardwareControl, SigintStopsSafely) {
  const trajectory::Trajectory traj = first_seconds("AG02", 3.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 3.0;
  const std::string csv = (dir_ / "sigint.csv").string();
  StopSignals signals;
  const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig&) { std::raise(SIGINT); });
  EXPECT_EQ(r.reason, StopReason::signal) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_TRUE(r.torque_off_confirmed);
  EXPECT_GT(r.trajectory_time, 0.2);
  EXPECT_LT(r.trajectory_time, 1.5);
  rig.expect_safe();
  expect_log(r, csv);
}

// Moves the rig's clock on by `seconds`, then pings: the twin's plant integrates up to each
// instruction's arrival, so this lets the arm move as its servos' state (torque off) says.
void let_time_pass(Rig& rig, double seconds) {
  const std::atomic<int> no_stop{0};
  rig.clock.sleep_until(rig.clock.now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(seconds)),
                        no_stop, 0);
  for (int attempt = 0; attempt < 5; ++attempt)
    if (rig.bus.ping(rig.hw.ids()[0], std::chrono::steady_clock::now() + std::chrono::seconds(1)).has_data()) return;
  ADD_FAILURE() << "the arm's servos did not answer a ping";
}

// How far the arm moved from the last logged pose (deg, the largest joint).
double moved_deg(const Rig& rig, const std::string& csv) {
  const io::Log log = io::read_log(csv);
  const int last = log.samples() - 1;
  double worst = 0;
  for (int j = 0; j < Model::nq; ++j) worst = std::max(worst, std::abs(rig.backend->q()(j) - log.q(last, j)));
  return worst * kDeg;
}

// Why hold is the default: the same SIGINT stop, torque off at once, hold on PD alone, and hold
// with the model's gravity (a model feedforward holding the twin's true parameters). The twin's
// arm is gravity-loaded: with torque off it falls within a fraction of a second; held, it stays
// where it stopped for the hold time (the servos' positions and the plant's own say so) and falls
// only after. On PD alone it sags by the PD's static error: gravity / (M_hat K_P) per joint (the
// true gravity at the stop pose), plus the stop of its motion, |qd| / (e w) for critically
// damped error dynamics (K_P = w^2); with gravity fed forward only the motion's part is left.
TEST_F(HardwareControl, HoldKeepsAGravityLoadedArmWhereTorqueOffLetsItFall) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  const double lsb = 2 * 3.14159265358979323846 / 4096;
  struct Case {
    const char* name;
    StopAction action;
    bool gravity;
  };
  for (const Case& c : {Case{"torque_off", StopAction::torque_off, false}, Case{"hold_pd", StopAction::hold, false},
                        Case{"hold_gravity", StopAction::hold, true}}) {
    SCOPED_TRACE(c.name);
    hw_.safety.at_stop = c.action;
    hw_.safety.hold_time = 0.6;
    Rig rig(twin_, hw_, traj);
    ControlOptions o = options();
    o.seconds = 2.0;
    if (c.gravity) o.feedforward = model_feedforward<Model>(rig.backend->truth().phi);
    const std::string csv = (dir_ / fmt::format("at_stop_{}.csv", c.name)).string();
    StopSignals signals;
    const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig&) { std::raise(SIGINT); });
    ASSERT_EQ(r.reason, StopReason::signal) << r.message;
    EXPECT_EQ(r.stop_action, c.action) << r.at_stop;
    EXPECT_TRUE(r.torque_off_confirmed);
    rig.expect_safe();
    expect_log(r, csv);
    const io::Log log = io::read_log(csv);
    const int last = log.samples() - 1;
    // The sag the PD allows at the stop pose, from the twin's true gravity.
    Eigen::Matrix<double, Model::nq, 1> q_stop = log.q.row(last).transpose(), g;
    Model::inverse_dynamics(q_stop, Eigen::Matrix<double, Model::nq, 1>::Zero(),
                            Eigen::Matrix<double, Model::nq, 1>::Zero(), rig.backend->truth().phi, g);
    double allowed = 0;
    for (int j = 0; j < Model::nq; ++j) {
      const double w = std::sqrt(gains_.kp(j));
      const double sag = c.gravity ? 0.0 : std::abs(g(j)) / (gains_.inertia(j) * gains_.kp(j));
      allowed = std::max(allowed, 1.25 * (sag + std::abs(log.qd(last, j)) / (std::exp(1.0) * w)) + 2 * lsb);
    }
    const double at_torque_off = moved_deg(rig, csv);  // the plant when torque went off
    let_time_pass(rig, 0.4);
    const double later = moved_deg(rig, csv);
    std::printf(
        "%s: %s; the plant moved %.2f deg from the stop pose by torque off, %.2f deg 0.4 s later (allowed while "
        "held: %.2f deg)\n",
        c.name, r.at_stop.c_str(), at_torque_off, later, allowed * kDeg);
    if (c.action == StopAction::hold) {
      EXPECT_NEAR(r.held, 0.6, 1e-9) << r.at_stop;
      EXPECT_LE(r.hold_deviation, allowed) << r.at_stop;
      EXPECT_LE(at_torque_off, allowed * kDeg);
    }
    EXPECT_GT(later, 10.0);  // unheld, the arm falls: tens of degrees in 0.4 s
    EXPECT_GT(later, 5 * at_torque_off);
  }
}

TEST_F(HardwareControl, ASecondSigintEndsTheHold) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  hw_.safety.hold_time = 30;  // only the second request can end it within the test's time
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "second_sigint.csv").string();
  StopSignals signals;
  const ControlResult r = run(rig, traj, csv, o, 0.5, [](Rig&) {
    std::raise(SIGINT);
    // A deliberate second request: past the escalation delay (a quicker one is the same request).
    std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(kStopEscalationDelay * 1e3) + 200));
    std::raise(SIGINT);
  });
  EXPECT_EQ(r.reason, StopReason::signal) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_NE(r.at_stop.find("a further stop request"), std::string::npos) << r.at_stop;
  EXPECT_LT(r.held, 20.0);
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

// GNU timeout and systemd send SIGTERM to the process and then to its group, microseconds
// apart: one request. The hold runs its whole time (on the real arm the alternative is torque off
// after 1 ms and a falling arm); the same pair of signals, sent the way a process-group kill
// reaches the process (kill(pid) then again), and a SIGINT right behind a SIGTERM, alike.
TEST_F(HardwareControl, SignalsMillisecondsApartAreOneStopRequest) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  hw_.safety.hold_time = 1.0;
  for (const auto& [name, second] :
       {std::pair<const char*, int>{"sigterm_pair", SIGTERM}, {"sigterm_sigint", SIGINT}}) {
    Rig rig(twin_, hw_, traj);
    ControlOptions o = options();
    o.seconds = 2.0;
    const std::string csv = (dir_ / fmt::format("{}.csv", name)).string();
    StopSignals signals;
    const ControlResult r = run(rig, traj, csv, o, 0.5, [second = second](Rig&) {
      ::kill(::getpid(), SIGTERM);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      ::kill(::getpid(), second);
    });
    EXPECT_EQ(r.reason, StopReason::signal) << r.message;
    EXPECT_EQ(r.stop_action, StopAction::hold);
    EXPECT_NEAR(r.held, 1.0, 1e-9) << name << ": " << r.at_stop;
    EXPECT_EQ(r.at_stop.find("ended early"), std::string::npos) << name << ": " << r.at_stop;
    EXPECT_TRUE(r.torque_off_confirmed);
    rig.expect_safe();
    expect_log(r, csv);
  }
}

// A SIGTERM that follows the first after the escalation delay is a new request: it ends the hold.
TEST_F(HardwareControl, ASigtermAfterTheDelayEndsTheHold) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  hw_.safety.hold_time = 30;
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "late_sigterm.csv").string();
  StopSignals signals;
  const auto delay = std::chrono::milliseconds(static_cast<int>(kStopEscalationDelay * 1e3) + 200);
  std::atomic<std::chrono::steady_clock::rep> first{0};
  const ControlResult r = run(rig, traj, csv, o, 0.5, [&first, delay](Rig&) {
    first = std::chrono::steady_clock::now().time_since_epoch().count();
    ::kill(::getpid(), SIGTERM);
    std::this_thread::sleep_for(delay);
    ::kill(::getpid(), SIGTERM);
  });
  const auto ended = std::chrono::steady_clock::now();
  EXPECT_EQ(r.reason, StopReason::signal) << r.message;
  EXPECT_NE(r.at_stop.find("a further stop request"), std::string::npos) << r.at_stop;
  // The first signal did not end the hold: it lasted until the second, `delay` later in real
  // time (the rig's clock leaves out the time a loaded host kept the loop waiting, so r.held
  // may be less).
  EXPECT_GE(ended - std::chrono::steady_clock::time_point(std::chrono::steady_clock::duration(first.load())), delay)
      << r.at_stop;
  EXPECT_GT(r.held, 0.0) << r.at_stop;
  EXPECT_LT(r.held, 20.0) << r.at_stop;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
}

// A stop in the pre-roll, before the trajectory's first row: torque was on, so the pose is held;
// the log has no rows, its sidecar says why.
TEST_F(HardwareControl, AStopBeforeTheTrajectoryLeavesAnEmptyLogThatSaysWhy) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  const std::string csv = (dir_ / "pre_roll.csv").string();
  StopSignals signals;
  const ControlResult r = run(rig, traj, csv, o, -0.3, [](Rig&) { std::raise(SIGINT); });
  EXPECT_EQ(r.reason, StopReason::signal) << r.message;
  EXPECT_EQ(r.rows, 0);
  EXPECT_EQ(r.stop_action, StopAction::hold);
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

// Every signal whose default would end the process stops the run as SIGINT does: the stop pose
// held, then torque off, the stop in the log's notes and the signal named (an SSH session that
// drops sends SIGHUP, Ctrl-\ SIGQUIT). Without a handler each of these ends the test program.
TEST_F(HardwareControl, EverySignalThatWouldEndTheProcessStopsLikeSigint) {
  const trajectory::Trajectory traj = first_seconds("AG02", 1.0);
  for (const auto& [sig, name] :
       {std::pair<int, const char*>{SIGHUP, "SIGHUP"}, {SIGQUIT, "SIGQUIT"}, {SIGUSR1, "SIGUSR1"}}) {
    SCOPED_TRACE(name);
    Rig rig(twin_, hw_, traj);
    ControlOptions o = options();
    o.seconds = 1.0;
    const std::string csv = (dir_ / fmt::format("{}.csv", name)).string();
    StopSignals signals;
    const ControlResult r = run(rig, traj, csv, o, 0.3, [sig = sig](Rig&) { ::kill(::getpid(), sig); });
    EXPECT_EQ(r.reason, StopReason::signal) << r.message;
    EXPECT_NE(r.message.find(name), std::string::npos) << r.message;
    EXPECT_EQ(r.stop_action, StopAction::hold) << r.at_stop;
    EXPECT_NEAR(r.held, hw_.safety.hold_time, 1e-9) << r.at_stop;
    EXPECT_TRUE(r.torque_off_confirmed);
    rig.expect_safe();
    expect_log(r, csv);
  }
  // The rest of the list: a handler is installed for each while StopSignals lives, and the
  // previous disposition is back after.
  {
    StopSignals signals;
    for (int sig : stop_signals()) {
      struct sigaction now {};
      sigaction(sig, nullptr, &now);
      EXPECT_TRUE(now.sa_flags & SA_SIGINFO) << "signal " << sig << " has no stop handler";
    }
  }
  struct sigaction after {};
  sigaction(SIGHUP, nullptr, &after);
  EXPECT_EQ(after.sa_handler, SIG_DFL);
}

// A closed pipe (dynid control ... | head -1) raises SIGPIPE at the next write: ignored while the
// arm runs, the write fails instead and the run goes on to its end.
TEST_F(HardwareControl, AClosedPipeDoesNotEndTheRun) {
  const trajectory::Trajectory traj = first_seconds("AG02", 1.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 1.0;
  const std::string csv = (dir_ / "sigpipe.csv").string();
  StopSignals signals;
  std::atomic<long> written{1};
  const ControlResult r = run(rig, traj, csv, o, 0.3, [&written](Rig&) {
    int fd[2];
    if (::pipe(fd) != 0) return;
    ::close(fd[0]);
    written = ::write(fd[1], "x", 1);  // SIGPIPE: would end the process
    ::close(fd[1]);
  });
  EXPECT_EQ(written.load(), -1);
  EXPECT_EQ(r.reason, StopReason::completed) << r.message;
  EXPECT_TRUE(r.torque_off_confirmed);
  rig.expect_safe();
  expect_log(r, csv);
}

// SIGKILL (or a crash) ends the controller with no stop at all: the servos' own Bus
// Watchdog(98), which the loop sets before torque on (safety.bus_watchdog), stops them once the
// bus stays silent that long. The controller runs in a child process on the emulated servos
// (wall clock); the parent kills it in the middle of the trajectory and reads the servos back.
TEST_F(HardwareControl, ASigkilledControllerLeavesTheServosToTheirBusWatchdog) {
  const trajectory::Trajectory traj = first_seconds("AG02", 3.0);
  ASSERT_NEAR(hw_.safety.bus_watchdog, 0.1, 1e-12);  // the default: 5 units of 20 ms
  Rig rig(twin_, hw_, traj, RigClock::wall);
  const std::string csv = (dir_ / "killed.csv").string();
  ControlOptions o = options();
  o.seconds = 3.0;
  o.verbose = false;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the controller: only its own work, then _exit (no test machinery)
    run_control(rig.bus, hw_, joints(), gains_, traj, csv, o);
    ::_exit(0);
  }
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  const std::uint8_t id = hw_.ids().front();
  const auto start = std::chrono::steady_clock::now();
  while (since(start) < 20 &&
         !(rig.virt.value(id, xs::kTorqueEnable) == 1 && rig.virt.value(id, xs::kBusWatchdog) == 5))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(rig.virt.value(id, xs::kBusWatchdog), 5) << "the controller never armed the servos' bus watchdog";
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // the loop runs the trajectory
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "the controller ended before it was killed";
  const auto killed = std::chrono::steady_clock::now();
  // Within the watchdog's 100 ms (and the emulation's 2 ms check) every servo has stopped: its
  // item reads -1, it drives no current, and a new goal is refused until the watchdog is cleared.
  for (std::uint8_t s : hw_.ids()) {
    while (since(killed) < 2 && rig.virt.value(s, xs::kBusWatchdog) != -1)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_EQ(rig.virt.value(s, xs::kBusWatchdog), -1) << "servo " << int(s);
    EXPECT_EQ(rig.virt.value(s, xs::kTorqueEnable), 1) << "servo " << int(s);  // stopped, not switched off
  }
  EXPECT_LT(since(killed), 0.5);
  for (std::uint8_t s : hw_.ids()) {
    const auto r =
        rig.bus.read(s, xs::kPresentCurrent, std::chrono::steady_clock::now() + std::chrono::milliseconds(200));
    ASSERT_TRUE(r.has_data()) << "servo " << int(s);
    EXPECT_EQ(r.get<std::int16_t>(0), 0) << "servo " << int(s) << " still drives its motor";
  }
  const auto refused =
      rig.bus.write(id, xs::kGoalCurrent, 10, std::chrono::steady_clock::now() + std::chrono::milliseconds(200));
  EXPECT_EQ(refused.outcome, dynamixel::Outcome::error_status);
  // Torque off still works on a tripped servo; clearing the watchdog (as the next run's setup
  // does) makes its goal writable again.
  EXPECT_TRUE(safe_stop(rig.bus, hw_));
  for (std::uint8_t s : hw_.ids()) {
    EXPECT_EQ(rig.virt.value(s, xs::kTorqueEnable), 0) << "servo " << int(s);
    EXPECT_TRUE(rig.bus.write(s, xs::kBusWatchdog, 0, std::chrono::steady_clock::now() + std::chrono::milliseconds(200))
                    .has_data());
  }
  EXPECT_TRUE(safe_stop(rig.bus, hw_));
  rig.expect_safe();
}

// A computer that stalls the loop past the servos' bus watchdog has let them stop: after the gap
// the loop reads the item back and ends the run as a watchdog stop, torque off at once. The
// stall is the loop's own (a feedforward that sleeps 150 ms once), on the wall clock.
TEST_F(HardwareControl, AStallPastTheBusWatchdogStopsTheRun) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj, RigClock::wall);
  ControlOptions o = options();
  o.seconds = 2.0;
  o.clock = &steady_loop_clock();
  std::atomic<double> timeline{-1e9};
  std::atomic<bool> stalled{false};
  const control::FfpdGains g = gains_;
  o.feedforward = [&timeline, &stalled, g](const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                           const Eigen::VectorXd& qdd, Eigen::VectorXd& tau) {
    tau = g.inertia.cwiseProduct(qdd) + g.damping.cwiseProduct(qd);  // FF+PD's own realization
    if (timeline.load() >= 0.3 && !stalled.exchange(true)) std::this_thread::sleep_for(std::chrono::milliseconds(150));
    (void)q;
  };
  o.timeline = &timeline;
  const std::string csv = (dir_ / "stall.csv").string();
  const ControlResult r = run_control(rig.bus, hw_, joints(), gains_, traj, csv, o);
  EXPECT_TRUE(stalled.load());
  EXPECT_EQ(r.reason, StopReason::bus_watchdog) << r.message;
  EXPECT_NE(r.message.find("stopped by its bus watchdog"), std::string::npos) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::torque_off) << r.at_stop;
  EXPECT_LT(r.trajectory_time, 0.5);
  EXPECT_TRUE(r.torque_off_confirmed);
  expect_log(r, csv);
}

// The disk fills up in the middle of a run (the file size limit, which fails a write as a full
// disk does): the run stops as an error naming the log, holds, turns torque off and reports
// all of it; the log on disk ends on its last whole row and its sidecar says it is incomplete.
// It used to end with only "cannot write the log", no stop report, and a CSV cut mid-number.
TEST_F(HardwareControl, AFullDiskStopsTheRunSafelyAndLeavesAWholeLog) {
  const trajectory::Trajectory traj = first_seconds("AG02", 2.0);
  Rig rig(twin_, hw_, traj);
  ControlOptions o = options();
  o.seconds = 2.0;
  o.log_flush = std::chrono::milliseconds(20);
  const std::string csv = (dir_ / "full.csv").string();
  struct rlimit saved {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = saved;
  small.rlim_cur = 200'000;  // about 0.4 s of rows of 8 joints
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const ControlResult r = run(rig, traj, csv, o);
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, previous);
  EXPECT_EQ(r.reason, StopReason::error) << r.message;
  EXPECT_NE(r.message.find("cannot write the log"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("full.csv"), std::string::npos) << r.message;
  EXPECT_EQ(r.stop_action, StopAction::hold) << r.at_stop;
  EXPECT_TRUE(r.torque_off_confirmed);
  EXPECT_LT(r.trajectory_time, 1.5);
  rig.expect_safe();
  const io::Log log = io::read_log(csv);
  EXPECT_EQ(log.samples(), r.rows);
  EXPECT_GT(r.rows, 100);
  EXPECT_NE(log.meta.notes.find("LOG INCOMPLETE"), std::string::npos) << log.meta.notes;
  EXPECT_NE(log.meta.notes.find("at stop: " + r.at_stop), std::string::npos) << log.meta.notes;
  std::ifstream in(csv, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.back(), '\n');
}

}  // namespace
}  // namespace symoro::hardware
