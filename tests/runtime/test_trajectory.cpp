// The identification trajectory generator (paper, Appendix B): the normalized profile, the
// synchronized moves, the 43 CRANE-X7 trajectories of robots/crane_x7/trajectories.yaml, the
// reference files, and the design file's error reporting.
#include <symoro/crane_x7.hpp>
#include <symoro/trajectory/design.hpp>
#include <symoro/trajectory/fourier.hpp>
#include <symoro/trajectory/move.hpp>
#include <symoro/trajectory/trajectory.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <unistd.h>

#include "symoro/error.hpp"

namespace symoro::trajectory {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = 3.14159265358979323846 / 180.0;
const fs::path kDesignFile = fs::path(SYMORO_ROBOTS_DIR) / "crane_x7" / "trajectories.yaml";

std::vector<JointInfo> crane_joints() {
  return {symoro::crane_x7::Model::joints.begin(), symoro::crane_x7::Model::joints.end()};
}

const TrajectoryDesign& design() {
  static const TrajectoryDesign d = TrajectoryDesign::read(kDesignFile, crane_joints());
  return d;
}

const std::vector<Trajectory>& all() {
  static const std::vector<Trajectory> t = design().build_all();
  return t;
}

const Trajectory& named(const std::string& name) {
  for (const auto& t : all())
    if (t.name == name) return t;
  throw std::runtime_error("no trajectory " + name);
}

// The design file's own numbers, read independently of the generator.
const YAML::Node& file() {
  static const YAML::Node root = YAML::LoadFile(kDesignFile.string());
  return root;
}

Eigen::VectorXd degrees_vector(const YAML::Node& list) {
  Eigen::VectorXd v(list.size());
  for (std::size_t k = 0; k < list.size(); ++k) v[k] = list[k].as<double>() * kDeg;
  return v;
}

Eigen::VectorXd posture(const std::string& name) { return degrees_vector(file()["postures"][name]); }

struct State {
  Eigen::VectorXd q, qd, qdd;
};

State at(const Trajectory& t, double time) {
  State s{Eigen::VectorXd(t.joints()), Eigen::VectorXd(t.joints()), Eigen::VectorXd(t.joints())};
  t.evaluate(time, s.q, s.qd, s.qdd);
  return s;
}

// ---------------------------------------------------------------- profile

struct Limits {
  double velocity, acceleration;
};
// With a cruise (2 v^2 / a <= 1) and without.
const std::vector<Limits> kCruising = {{0.5, 4.0}, {1.0, 4.0}, {0.2, 0.5}};
const std::vector<Limits> kShort = {{2.0, 4.0}, {1.5, 1.0}, {10.0, 50.0}};

TEST(Profile, StartsAndEndsAtRestAtZeroAndOne) {
  std::vector<Limits> all_limits = kCruising;
  all_limits.insert(all_limits.end(), kShort.begin(), kShort.end());
  for (const auto& lim : all_limits) {
    const Profile p = Profile::plan(lim.velocity, lim.acceleration);
    double s, sd, sdd;
    p.evaluate(0.0, s, sd, sdd);
    EXPECT_EQ(s, 0.0);
    EXPECT_EQ(sd, 0.0);
    EXPECT_EQ(sdd, 0.0);
    p.evaluate(p.duration, s, sd, sdd);
    EXPECT_EQ(s, 1.0);
    EXPECT_EQ(sd, 0.0);
    EXPECT_EQ(sdd, 0.0);
  }
}

TEST(Profile, CruisesAtTheVelocityLimitAfterRampsAtTheAccelerationLimit) {
  for (const auto& lim : kCruising) {
    const Profile p = Profile::plan(lim.velocity, lim.acceleration);
    ASSERT_GT(p.cruise, 0);
    EXPECT_NEAR(p.ramp, 2 * lim.velocity / lim.acceleration, 1e-15);
    EXPECT_NEAR(p.duration, 1 / lim.velocity + 2 * lim.velocity / lim.acceleration, 1e-14);
    EXPECT_NEAR(p.peak_velocity(), lim.velocity, 1e-14);
    EXPECT_NEAR(p.peak_acceleration(), lim.acceleration, 1e-13);
    // Sampled: the largest |sd| and |sdd| are the limits, reached in the cruise and mid-ramp.
    double max_sd = 0, max_sdd = 0;
    for (int k = 0; k <= 4000; ++k) {
      double s, sd, sdd;
      p.evaluate(p.duration * k / 4000.0, s, sd, sdd);
      max_sd = std::max(max_sd, std::abs(sd));
      max_sdd = std::max(max_sdd, std::abs(sdd));
      EXPECT_GE(sd, 0.0);
      EXPECT_GE(s, 0.0);
      EXPECT_LE(s, 1.0);
    }
    double s, sd, sdd;
    p.evaluate(p.ramp / 2, s, sd, sdd);
    EXPECT_NEAR(sdd, lim.acceleration, 1e-12);
    p.evaluate(p.duration - p.ramp / 2, s, sd, sdd);
    EXPECT_NEAR(sdd, -lim.acceleration, 1e-12);
    p.evaluate(p.ramp + p.cruise / 2, s, sd, sdd);
    EXPECT_NEAR(sd, lim.velocity, 1e-14);
    EXPECT_EQ(sdd, 0.0);
    EXPECT_NEAR(max_sd, lim.velocity, 1e-12);
    EXPECT_LE(max_sdd, lim.acceleration * (1 + 1e-12));
  }
}

TEST(Profile, ShortMoveLowersThePeakVelocityAndHasNoCruise) {
  for (const auto& lim : kShort) {
    const Profile p = Profile::plan(lim.velocity, lim.acceleration);
    EXPECT_EQ(p.cruise, 0.0);
    EXPECT_NEAR(p.peak_acceleration(), lim.acceleration, 1e-12);
    EXPECT_NEAR(p.peak_velocity(), std::sqrt(lim.acceleration / 2), 1e-12);
    EXPECT_LT(p.peak_velocity(), lim.velocity);
    EXPECT_NEAR(p.duration, 2 * std::sqrt(2 / lim.acceleration), 1e-12);
    double s, sd, sdd;
    p.evaluate(p.ramp, s, sd, sdd);  // the middle of the move
    EXPECT_NEAR(s, 0.5, 1e-15);
    EXPECT_NEAR(sd, p.peak_velocity(), 1e-14);
    EXPECT_NEAR(sdd, 0.0, 1e-12);
  }
}

TEST(Profile, AccelerationIsContinuousIncludingPhaseBoundaries) {
  for (const auto& lim : {kCruising[0], kCruising[2], kShort[0], kShort[2]}) {
    const Profile p = Profile::plan(lim.velocity, lim.acceleration);
    std::vector<double> times = {0.0, p.ramp, p.ramp + p.cruise, p.duration - 2e-9};
    for (int k = 0; k < 1000; ++k) times.push_back(p.duration * k / 1000.0);
    // The jerk is at most pi a / ramp: over 1e-9 s sdd changes by far less than 1e-6 a.
    const double bound = 1e-6 * lim.acceleration;
    for (double t : times) {
      double s0, sd0, sdd0, s1, sd1, sdd1;
      p.evaluate(t, s0, sd0, sdd0);
      p.evaluate(t + 1e-9, s1, sd1, sdd1);
      EXPECT_LT(std::abs(sdd1 - sdd0), bound) << "t = " << t;
      EXPECT_LT(std::abs(sd1 - sd0), bound) << "t = " << t;
      EXPECT_LT(std::abs(s1 - s0), bound) << "t = " << t;
    }
  }
}

TEST(Profile, DerivativesMatchCentralDifferences) {
  const double h = 1e-6;
  for (const auto& lim : {kCruising[0], kShort[0]}) {
    const Profile p = Profile::plan(lim.velocity, lim.acceleration);
    for (int k = 1; k < 500; ++k) {
      const double t = p.duration * k / 500.0;
      double s, sd, sdd, sp, sdp, sddp, sm, sdm, sddm;
      p.evaluate(t, s, sd, sdd);
      p.evaluate(t + h, sp, sdp, sddp);
      p.evaluate(t - h, sm, sdm, sddm);
      EXPECT_NEAR((sp - sm) / (2 * h), sd, 1e-7) << "t = " << t;
      EXPECT_NEAR((sdp - sdm) / (2 * h), sdd, 1e-6 * lim.acceleration) << "t = " << t;
    }
  }
}

TEST(Profile, RejectsNonPositiveLimits) {
  EXPECT_THROW(Profile::plan(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(Profile::plan(1.0, -1.0), std::invalid_argument);
  EXPECT_THROW(Profile::plan(NAN, 1.0), std::invalid_argument);
}

// ---------------------------------------------------------------- synchronized moves

TEST(Move, TheSlowestJointSetsTheTimingAndNoJointExceedsItsLimits) {
  Eigen::VectorXd from(3), to(3), v(3), a(3);
  from << 0.0, 1.0, -0.5;
  to << 1.0, 0.5, -0.5;  // joint 3 stays
  v << 2.0, 0.5, 0.1;    // joint 2: 0.5 rad/s over 0.5 rad is the tighter velocity (1/s)
  a << 40.0, 4.0, 0.1;   // joint 2: 4 rad/s^2 over 0.5 rad is the tighter acceleration
  const Segment seg = plan_move(2.0, from, to, v, a);
  EXPECT_EQ(seg.start, 2.0);
  const Profile expected = Profile::plan(1.0, 8.0);
  EXPECT_EQ(seg.profile.duration, expected.duration);
  EXPECT_EQ(seg.profile.ramp, expected.ramp);
  ASSERT_GT(seg.profile.cruise, 0);
  // Joint 2 cruises at its velocity limit and peaks at its acceleration limit; joint 1 below.
  EXPECT_NEAR(0.5 * seg.profile.peak_velocity(), 0.5, 1e-14);
  EXPECT_NEAR(0.5 * seg.profile.peak_acceleration(), 4.0, 1e-12);
  EXPECT_LT(1.0 * seg.profile.peak_velocity(), 2.0);
  EXPECT_LT(1.0 * seg.profile.peak_acceleration(), 40.0);

  Trajectory t;
  t.segments = {seg};
  t.segments.front().start = 0;
  const State mid = at(t, seg.profile.ramp + seg.profile.cruise / 2);
  EXPECT_NEAR(mid.qd[0], 1.0, 1e-14);
  EXPECT_NEAR(mid.qd[1], -0.5, 1e-14);
  EXPECT_EQ(mid.qd[2], 0.0);
  EXPECT_EQ(at(t, seg.profile.duration).q, to);
}

TEST(Move, NoDisplacementGivesAnEmptySegment) {
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(2, 0.3), lim = Eigen::VectorXd::Ones(2);
  const Segment seg = plan_move(1.0, q, q, lim, lim);
  EXPECT_FALSE(seg.profile.moves());
  EXPECT_EQ(seg.profile.duration, 0.0);
}

// ---------------------------------------------------------------- the 43 trajectories

TEST(Design, FamiliesHaveTheirCountsAndNamesInOrder) {
  std::vector<std::string> expected;
  for (const std::string family : {"PA", "PB", "PC"})
    for (int k = 1; k <= 11; ++k) expected.push_back(family + (k < 10 ? "0" : "") + std::to_string(k));
  for (int k = 1; k <= 5; ++k) expected.push_back("AP0" + std::to_string(k));
  for (int k = 1; k <= 2; ++k) expected.push_back("AG0" + std::to_string(k));
  for (int k = 1; k <= 3; ++k) expected.push_back("V0" + std::to_string(k));
  ASSERT_EQ(expected.size(), 43u);
  EXPECT_EQ(design().names(), expected);

  std::map<std::string, int> counts;
  ASSERT_EQ(all().size(), 43u);
  for (std::size_t k = 0; k < all().size(); ++k) {
    EXPECT_EQ(all()[k].name, expected[k]);
    ++counts[all()[k].family];
    EXPECT_FALSE(all()[k].description.empty());
  }
  const std::map<std::string, int> expected_counts = {{"PA", 11}, {"PB", 11}, {"PC", 11},
                                                      {"AP", 5},  {"AG", 2},  {"V", 3}};
  EXPECT_EQ(counts, expected_counts);
}

TEST(Design, PostureFamiliesStartAndEndAtTheirPosture) {
  const std::map<std::string, std::string> posture_of = {{"PA", "A"}, {"PB", "B"}, {"PC", "C"}};
  for (const auto& t : all()) {
    const auto found = posture_of.find(t.family);
    if (found == posture_of.end()) continue;
    const Eigen::VectorXd expected = posture(found->second);
    EXPECT_TRUE(at(t, 0.0).q.isApprox(expected, 1e-15)) << t.name;
    EXPECT_EQ(at(t, 0.0).q, expected) << t.name;
    EXPECT_EQ(at(t, t.duration()).q, expected) << t.name;
  }
  // AP01-AP03 at A, B, C; AP04-AP05 at C.
  const std::vector<std::pair<std::string, std::string>> ap = {
      {"AP01", "A"}, {"AP02", "B"}, {"AP03", "C"}, {"AP04", "C"}, {"AP05", "C"}};
  for (const auto& [name, p] : ap) EXPECT_EQ(at(named(name), 0.0).q, posture(p)) << name;
}

TEST(Design, EveryTrajectoryStartsAndEndsAtRestWithAHoldOfAtLeastOneSecond) {
  for (const auto& t : all()) {
    ASSERT_GE(t.segments.size(), 3u) << t.name;
    const Segment& first = t.segments.front();
    const Segment& last = t.segments.back();
    EXPECT_FALSE(first.profile.moves()) << t.name;
    EXPECT_FALSE(last.profile.moves()) << t.name;
    EXPECT_GE(first.profile.duration, 1.0) << t.name;
    EXPECT_GE(last.profile.duration, 1.0) << t.name;
    EXPECT_EQ(first.start, 0.0) << t.name;
    for (double time : {0.0, 0.5, 1.0, t.duration() - 1.0, t.duration() - 0.5, t.duration()}) {
      const State s = at(t, time);
      EXPECT_EQ(s.qd.norm(), 0.0) << t.name << " t = " << time;
      EXPECT_EQ(s.qdd.norm(), 0.0) << t.name << " t = " << time;
    }
    // Contiguous segments.
    for (std::size_t k = 1; k < t.segments.size(); ++k) {
      EXPECT_EQ(t.segments[k].start, t.segments[k - 1].end()) << t.name;
      EXPECT_EQ(t.segments[k].from, t.segments[k - 1].to) << t.name;
    }
  }
}

TEST(Design, EveryTrajectoryStaysInsideThePositionAndVelocityLimits) {
  const double margin = file()["limits"]["position_margin"].as<double>() * kDeg;
  EXPECT_EQ(margin, 2 * kDeg);
  const auto joints = crane_joints();
  for (const auto& t : all()) {
    Eigen::VectorXd max_speed = Eigen::VectorXd::Zero(t.joints());
    for (double time = 0; time <= t.duration(); time += 0.002) {
      const State s = at(t, time);
      for (int j = 0; j < t.joints(); ++j) {
        ASSERT_GE(s.q[j], joints[j].lower + margin) << t.name << " joint " << j + 1 << " t = " << time;
        ASSERT_LE(s.q[j], joints[j].upper - margin) << t.name << " joint " << j + 1 << " t = " << time;
        ASSERT_LE(std::abs(s.qd[j]), joints[j].velocity) << t.name << " joint " << j + 1 << " t = " << time;
        max_speed[j] = std::max(max_speed[j], std::abs(s.qd[j]));
      }
    }
    // The nominal velocities at the highest speed factor bound every trajectory.
    EXPECT_LE(max_speed.maxCoeff(), 0.9 * 3.0 + 1e-12) << t.name;
    EXPECT_GT(max_speed.maxCoeff(), 0.5) << t.name;
  }
}

TEST(Design, DerivativesMatchCentralDifferencesAlongWholeTrajectories) {
  const double h = 1e-6;
  for (const std::string name : {"PA03", "PC11", "AP04", "AG02", "V03"}) {
    const Trajectory& t = named(name);
    double worst_qd = 0, worst_qdd = 0;
    for (double time = h; time < t.duration(); time += 0.0037) {
      const State s = at(t, time), plus = at(t, time + h), minus = at(t, time - h);
      worst_qd = std::max(worst_qd, ((plus.q - minus.q) / (2 * h) - s.qd).cwiseAbs().maxCoeff());
      worst_qdd = std::max(worst_qdd, ((plus.qd - minus.qd) / (2 * h) - s.qdd).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst_qd, 1e-7) << name;
    EXPECT_LT(worst_qdd, 1e-5) << name;  // accelerations reach 16 rad/s^2
  }
}

TEST(Design, SingleJointPrimitiveVisitsQbarMinusThenPlusTheAmplitude) {
  // PA01 sweeps P_1 .. P_8 at A; each primitive's moves end at qbar - a e_j, qbar + a e_j, qbar,
  // with qbar = A + c_j e_j (the hand is centered above its lower stop).
  const Trajectory& t = named("PA01");
  const Eigen::VectorXd amplitude = degrees_vector(file()["primitives"]["A"]["amplitude"]);
  const Eigen::VectorXd center = degrees_vector(file()["primitives"]["A"]["center"]);
  EXPECT_EQ(amplitude[0], 45 * kDeg);
  EXPECT_EQ(center[7], 40 * kDeg);
  for (int j = 0; j < 8; ++j) {
    const std::string label = "P" + std::to_string(j + 1) + "@A";
    std::vector<const Segment*> moves;
    for (const auto& s : t.segments)
      if (s.label == label && s.profile.moves()) moves.push_back(&s);
    ASSERT_EQ(moves.size(), 3u) << label;
    Eigen::VectorXd qbar = posture("A");
    qbar[j] += center[j];
    Eigen::VectorXd e = Eigen::VectorXd::Zero(8);
    e[j] = 1;
    EXPECT_TRUE(moves[0]->to.isApprox(qbar - amplitude[j] * e, 1e-15)) << label;
    EXPECT_TRUE(moves[1]->to.isApprox(qbar + amplitude[j] * e, 1e-15)) << label;
    EXPECT_EQ(moves[2]->to, qbar) << label;
    EXPECT_EQ(moves[0]->from, qbar) << label;
    // Evaluated, not just planned: the arm is there when each move ends, and only joint j moved.
    EXPECT_NEAR(at(t, moves[0]->end()).q[j], qbar[j] - amplitude[j], 1e-12) << label;
    EXPECT_NEAR(at(t, moves[1]->end()).q[j], qbar[j] + amplitude[j], 1e-12) << label;
    for (int other = 0; other < 8; ++other)
      if (other != j) {
        EXPECT_EQ(at(t, moves[1]->end()).q[other], qbar[other]) << label;
      }
  }
}

TEST(Design, AdjacentPairPrimitiveFollowsItsSigns) {
  // PB07 has P4,5(+,-) at B: delta = a4 e4 - a5 e5 around qbar = B + c4 e4.
  const Trajectory& t = named("PB07");
  const Eigen::VectorXd amplitude = degrees_vector(file()["primitives"]["B"]["amplitude"]);
  const Eigen::VectorXd center = degrees_vector(file()["primitives"]["B"]["center"]);
  std::vector<const Segment*> moves;
  for (const auto& s : t.segments)
    if (s.label == "P4,5(+,-)@B" && s.profile.moves()) moves.push_back(&s);
  ASSERT_EQ(moves.size(), 3u);
  Eigen::VectorXd qbar = posture("B");
  qbar[3] += center[3];
  qbar[4] += center[4];
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(8);
  delta[3] = amplitude[3];
  delta[4] = -amplitude[4];
  EXPECT_TRUE(moves[0]->to.isApprox(qbar - delta, 1e-15));
  EXPECT_TRUE(moves[1]->to.isApprox(qbar + delta, 1e-15));
  EXPECT_EQ(moves[2]->to, qbar);
  EXPECT_NEAR(moves[0]->to[3] / kDeg, -150.0, 1e-12);  // elbow from its folded posture ...
  EXPECT_NEAR(moves[1]->to[3] / kDeg, -90.0, 1e-12);   // ... to 60 deg open
  EXPECT_NEAR(moves[1]->to[4] / kDeg, -60.0, 1e-12);   // while joint 5 turns the other way
}

TEST(Design, WristVariantSegmentsHoldJointSixAtTheVariant) {
  const double offset = file()["wrist_variant"]["offset"].as<double>() * kDeg;
  EXPECT_EQ(file()["wrist_variant"]["joint"].as<int>(), 6);
  EXPECT_NEAR(offset / kDeg, 87.0, 1e-12);  // about 90 deg, 1 deg inside the stop's margin
  for (const std::string family : {"PA", "PB", "PC"}) {
    for (const std::string number : {"10", "11"}) {
      const Trajectory& t = named(family + number);
      const Eigen::VectorXd base = posture(family.substr(1));
      int wrist_segments = 0;
      for (const auto& s : t.segments) {
        if (s.label.find("'") == std::string::npos) continue;
        ++wrist_segments;
        for (double time : {s.start, 0.5 * (s.start + s.end()), s.end()})
          EXPECT_NEAR(at(t, time).q[5], base[5] + offset, 1e-15) << t.name << " " << s.label;
      }
      EXPECT_GE(wrist_segments, 12) << t.name;
    }
  }
  // Outside wrist-variant segments, the posture trajectories keep joint 6 within its primitive.
  for (const auto& s : named("PA01").segments) EXPECT_LE(std::abs(s.to[5]), 45 * kDeg + 1e-15);
}

TEST(Design, SpeedLevelsReplayTheSamePathSlower) {
  // A speed factor stretches time: PA01 (level 1) and PA03 (level 3) have the same waypoints,
  // every move lasting 3 times longer (0.9 / 0.3 = 0.75 / 0.25 = 0.6 / 0.2).
  const Trajectory &slow = named("PA01"), &fast = named("PA03");
  ASSERT_EQ(slow.segments.size(), fast.segments.size());
  for (std::size_t k = 0; k < slow.segments.size(); ++k) {
    EXPECT_EQ(slow.segments[k].to, fast.segments[k].to);
    if (slow.segments[k].profile.moves()) {
      EXPECT_NEAR(slow.segments[k].profile.duration / fast.segments[k].profile.duration, 3.0, 1e-12);
    }
  }
  EXPECT_GT(slow.duration(), 2 * fast.duration());
  // P7 at level 3 (class large, factor 0.6) sweeps 180 deg, long enough to cruise at 0.6 x 3 rad/s.
  double peak = 0;
  for (const auto& s : fast.segments)
    if (s.label == "P7@A" && s.profile.moves()) {
      EXPECT_GT(s.profile.cruise, 0);
      peak = std::max(peak, std::abs(s.to[6] - s.from[6]) * s.profile.peak_velocity());
    }
  EXPECT_NEAR(peak, 0.6 * 3.0, 1e-12);
}

TEST(Design, AggregatesAndAdjacentPairFamilies) {
  const Trajectory& ag02 = named("AG02");
  EXPECT_GE(ag02.duration(), 100.0);
  EXPECT_LE(ag02.duration(), 120.0);
  // AP trajectories move pairs only; AG01 too.
  for (const std::string name : {"AP01", "AP02", "AP03", "AP04", "AP05", "AG01"})
    for (const auto& s : named(name).segments)
      if (s.label.rfind("P", 0) == 0) {
        EXPECT_NE(s.label.find(','), std::string::npos) << name << " " << s.label;
      }
  // AG02 mixes single-joint and pair primitives.
  int singles = 0, pairs = 0;
  for (const auto& s : ag02.segments)
    if (s.label.rfind("P", 0) == 0 && s.profile.moves()) ++(s.label.find(',') == std::string::npos ? singles : pairs);
  EXPECT_GT(singles, 0);
  EXPECT_GT(pairs, 0);
  // AP04 and AP05: the AP03 path at lower speed levels.
  EXPECT_GT(named("AP04").duration(), named("AP05").duration());
  EXPECT_GT(named("AP05").duration(), named("AP03").duration());
}

TEST(Design, ValidationTrajectoriesMoveManyAxesAtOnce) {
  // V01: all eight axes in every waypoint move; V02: groups of four arm joints plus the hand.
  auto moving_axes = [](const Segment& s) { return static_cast<int>((s.to - s.from).cwiseAbs().cwiseSign().sum()); };
  int v01_all = 0, v02_groups = 0;
  for (const auto& s : named("V01").segments)
    if (s.label.rfind("waypoint", 0) == 0 && s.profile.moves() && moving_axes(s) == 8) ++v01_all;
  for (const auto& s : named("V02").segments)
    if (s.label.rfind("waypoint", 0) == 0 && s.profile.moves() && moving_axes(s) == 5 && s.to[7] != s.from[7])
      ++v02_groups;
  EXPECT_GE(v01_all, 5);
  EXPECT_GE(v02_groups, 5);
  for (const std::string name : {"V01", "V02", "V03"})
    for (const auto& s : named(name).segments)
      EXPECT_EQ(s.label.find('@'), std::string::npos) << name << ": no primitives in validation";
}

TEST(Design, EvaluationOutsideTheTrajectoryHoldsItsEnds) {
  const Trajectory& t = named("V02");
  EXPECT_EQ(at(t, -3.0).q, at(t, 0.0).q);
  EXPECT_EQ(at(t, t.duration() + 5.0).q, at(t, t.duration()).q);
  EXPECT_EQ(at(t, t.duration() + 5.0).qd.norm(), 0.0);
}

TEST(Design, BuildingTwiceGivesIdenticalSamples) {
  const TrajectoryDesign again = TrajectoryDesign::read(kDesignFile, crane_joints());
  const auto second = again.build_all();
  ASSERT_EQ(second.size(), all().size());
  for (std::size_t k = 0; k < second.size(); ++k) {
    const io::Log a = reference_log(all()[k], 0.01, "crane_x7", std::vector<std::string>(8, "j"));
    const io::Log b = reference_log(second[k], 0.01, "crane_x7", std::vector<std::string>(8, "j"));
    EXPECT_EQ(a.time, b.time) << all()[k].name;
    EXPECT_EQ(a.q_ref, b.q_ref) << all()[k].name;
    EXPECT_EQ(a.qd_ref, b.qd_ref) << all()[k].name;
    EXPECT_EQ(a.qdd_ref, b.qdd_ref) << all()[k].name;
  }
}

// ---------------------------------------------------------------- reference files

TEST(ReferenceLog, SamplesEveryPeriodFromZeroToTheEndInclusive) {
  std::vector<std::string> names;
  for (const auto& j : crane_joints()) names.emplace_back(j.name);
  const Trajectory& t = named("AG02");
  for (double period : {0.001, 0.01, 0.04, 0.08}) {
    const io::Log log = reference_log(t, period, "crane_x7", names);
    const long steps = std::lround(t.duration() / period);
    ASSERT_EQ(log.samples(), steps + 1) << period;
    EXPECT_EQ(log.time[0], 0.0);
    EXPECT_EQ(log.time[log.samples() - 1], t.duration());
    EXPECT_EQ(log.time[1], period);
    EXPECT_EQ(log.time[steps - 1], static_cast<double>(steps - 1) * period);
    for (int k = 1; k < log.samples(); ++k) ASSERT_GT(log.time[k], log.time[k - 1]);
    EXPECT_EQ(log.meta.source, "reference");
    EXPECT_EQ(log.meta.trajectory, "AG02");
    EXPECT_EQ(log.meta.robot, "crane_x7");
    EXPECT_EQ(log.meta.joints, names);
    EXPECT_EQ(log.meta.sample_time, period);
    EXPECT_EQ(log.q.cols(), 0);
    EXPECT_EQ(log.qd.cols(), 0);
    EXPECT_EQ(log.tau.cols(), 0);
    EXPECT_EQ(log.q.rows(), log.samples());
    ASSERT_EQ(log.q_ref.cols(), 8);
    for (int k : {0, 17, log.samples() / 2, log.samples() - 1}) {
      const State s = at(t, log.time[k]);
      EXPECT_EQ(Eigen::VectorXd(log.q_ref.row(k).transpose()), s.q);
      EXPECT_EQ(Eigen::VectorXd(log.qd_ref.row(k).transpose()), s.qd);
      EXPECT_EQ(Eigen::VectorXd(log.qdd_ref.row(k).transpose()), s.qdd);
    }
    EXPECT_NO_THROW(io::validate_log(log, "AG02.csv"));
  }
  EXPECT_THROW(reference_log(t, 0.0, "crane_x7", names), std::invalid_argument);
  EXPECT_THROW(reference_log(t, 0.01, "crane_x7", {"only_one"}), std::invalid_argument);
}

// ---------------------------------------------------------------- design file errors

// A small valid design; the tests break one line at a time.
const std::string kSmallDesign = R"(robot: crane_x7
joints: [shoulder_pan, shoulder_tilt, upper_arm_twist, elbow, lower_arm_twist, wrist_tilt, wrist_twist, hand]
limits:
  position_margin: 2
  velocity: [2, 2, 2.5, 2.5, 3, 3, 3, 3]
  acceleration: [10, 10, 15, 15, 20, 20, 20, 20]
speed_factors:
  normal: [0.3, 0.6, 0.9]
  slow: [0.2, 0.4, 0.6]
joint_class: [slow, slow, normal, normal, normal, normal, normal, normal]
timing: {start_hold: 1.5, end_hold: 1.5, waypoint_dwell: 0.25, primitive_dwell: 0.5}
postures:
  A: [0, 0, 0, -90, 0, 0, 0, 0]
wrist_variant: {joint: 6, offset: 87}
primitives:
  A:
    amplitude: [45, 30, 45, 45, 60, 45, 90, 35]
    center: [0, 0, 0, 0, 0, 0, 0, 40]
patterns:
  singles: [{single: [1, 2, 3]}]
trajectories:
  - {name: PA01, posture: A, speed: 1, sequence: [{pattern: singles}]}
  - name: PA02
    posture: A
    speed: 3
    sequence:
      - {pair: [4, 5], signs: [1, -1]}
      - {single: [7], posture: A'}
      - {waypoints: [[10, 10, 10, -80, 10, 10, 10, 10]]}
)";

class BrokenDesign : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("symoro_trajectory_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& text) const {
    const fs::path p = dir_ / "trajectories.yaml";
    std::ofstream(p) << text;
    return p;
  }

  // kSmallDesign with `from` replaced by `to`.
  static std::string edit(const std::string& from, const std::string& to) {
    std::string text = kSmallDesign;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  }

  // The 1-based line of the first occurrence of `marker` in `text`.
  static int line_of(const std::string& text, const std::string& marker) {
    const auto at = text.find(marker);
    EXPECT_NE(at, std::string::npos) << marker;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
  }

  // Reading `text` fails at the line of `marker` with a message containing `message`.
  void expect_read_error(const std::string& text, const std::string& marker, const std::string& message) const {
    const fs::path p = write(text);
    try {
      TrajectoryDesign::read(p, crane_joints());
      ADD_FAILURE() << "no error; expected '" << message << "'";
    } catch (const DataError& e) {
      EXPECT_EQ(e.file(), p.string());
      EXPECT_EQ(e.line(), line_of(text, marker)) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      // "file:line: error: ", or "file:line:column: error: " for a YAML syntax error.
      const std::string what = e.what(), at = p.string() + ":" + std::to_string(line_of(text, marker)) + ":";
      EXPECT_EQ(what.rfind(at, 0), 0u) << what;
      std::size_t k = at.size();
      while (k < what.size() && std::isdigit(static_cast<unsigned char>(what[k]))) ++k;
      EXPECT_EQ(what.substr(k).rfind(k == at.size() ? " error: " : ": error: ", 0), 0u) << what;
    }
  }

  fs::path dir_;
};

TEST_F(BrokenDesign, TheSmallDesignIsValid) {
  const auto d = TrajectoryDesign::read(write(kSmallDesign), crane_joints());
  EXPECT_EQ(d.names(), (std::vector<std::string>{"PA01", "PA02"}));
  const auto t = d.build_all();
  EXPECT_EQ(t[1].family, "PA");
  // PA02: the pair, a transition to A' (joint 6 at 87 deg) for P7, then the waypoint.
  bool wrist = false;
  for (const auto& s : t[1].segments) {
    if (s.label != "P7@A'") continue;
    wrist = true;
    EXPECT_NEAR(s.to[5] / kDeg, 87, 1e-12);
  }
  EXPECT_TRUE(wrist);
}

TEST_F(BrokenDesign, UnknownKeysNameTheirLine) {
  expect_read_error(edit("patterns:", "colour: red\npatterns:"), "colour", "unknown key 'colour' in the design");
  expect_read_error(edit("    center: [0,", "    centre: [0,"), "centre",
                    "unknown key 'centre' in primitives.A; did you mean 'center'?");
  expect_read_error(edit("{single: [7], posture: A'}", "{single: [7], postur: A'}"), "postur:", "unknown key 'postur'");
  expect_read_error(edit("timing: {start_hold", "timing: {start_hld"), "timing",
                    "unknown key 'start_hld' in timing; did you mean 'start_hold'?");
}

TEST_F(BrokenDesign, WrongSizesNameTheirLine) {
  expect_read_error(edit("  A: [0, 0, 0, -90, 0, 0, 0, 0]", "  A: [0, 0, 0, -90, 0, 0, 0]"), "  A: [0, 0, 0, -90",
                    "must have 8 entries, not 7");
  expect_read_error(edit("  velocity: [2, 2, 2.5, 2.5, 3, 3, 3, 3]", "  velocity: [2, 2]"),
                    "  velocity:", "limits.velocity (one value per joint) must have 8 entries, not 2");
  expect_read_error(edit("[[10, 10, 10, -80, 10, 10, 10, 10]]", "[[10, 10, 10, -80, 10]]"), "[[10, 10, 10, -80",
                    "must have 8 entries, not 5");
  expect_read_error(edit("signs: [1, -1]", "signs: [1, -1, 1]"), "signs:", "signs must have 2 entries");
  expect_read_error(edit("  slow: [0.2, 0.4, 0.6]", "  slow: [0.2, 0.4]"), "  slow:", "has 2 levels");
}

TEST_F(BrokenDesign, UnknownNamesNameTheirLine) {
  expect_read_error(edit("posture: A'}", "posture: D}"), "posture: D", "unknown posture 'D'");
  expect_read_error(edit("{pattern: singles}", "{pattern: doubles}"), "doubles", "unknown pattern 'doubles'");
  expect_read_error(edit("[slow, slow, normal", "[slow, fast, normal"), "joint_class", "unknown speed class 'fast'");
  expect_read_error(edit("upper_arm_twist, elbow", "upper_arm_twist, knee"),
                    "joints:", "is 'elbow' in the robot, not 'knee'");
}

TEST_F(BrokenDesign, OutOfRangeValuesNameTheirLine) {
  expect_read_error(edit("{single: [1, 2, 3]}", "{single: [1, 9, 3]}"), "single: [1, 9",
                    "a joint number must be an integer in 1..8");
  expect_read_error(edit("{pair: [4, 5]", "{pair: [4, 6]"), "pair: [4, 6]", "adjacent joints [j, j+1], not [4, 6]");
  expect_read_error(edit("signs: [1, -1]", "signs: [1, 0]"), "signs:", "a sign must be 1 or -1");
  expect_read_error(edit("speed: 3", "speed: 4"), "speed: 4", "speed (a level) must be an integer in 1..3");
  expect_read_error(edit("start_hold: 1.5", "start_hold: 0.5"), "timing", "timing.start_hold must be at least 1");
  expect_read_error(edit("  A: [0, 0, 0, -90, 0, 0, 0, 0]", "  A: [0, 0, 0, -170, 0, 0, 0, 0]"), "  A: [0, 0, 0, -170",
                    "joint 4 (elbow) at -170 deg is outside");
  expect_read_error(edit("offset: 87", "offset: 89"), "wrist_variant", "the wrist variant A' puts joint 6 at 89 deg");
  expect_read_error(edit("velocity: [2, 2, 2.5", "velocity: [2, abc, 2.5"),
                    "  velocity:", "must be a number, not 'abc'");
  expect_read_error(edit("[[10, 10, 10, -80, 10, 10, 10, 10]]", "[[10, 10, 10, -80, 10, 10, 10, -10]]"),
                    "[[10, 10, 10, -80", "joint 8 (hand) at -10 deg is outside");
}

TEST_F(BrokenDesign, StructuralMistakesNameTheirLine) {
  expect_read_error(edit("  - {name: PA01, posture: A, speed: 1, sequence: [{pattern: singles}]}",
                         "  - {name: PA02, posture: A, speed: 1, sequence: [{pattern: singles}]}"),
                    "  - name: PA02", "duplicate trajectory name 'PA02'");
  expect_read_error(edit("{pattern: singles}]}", "{pattern: singles, single: [1]}]}"), "{pattern: singles, single",
                    "needs exactly one of pattern, single, pair, waypoints and fourier");
  expect_read_error(edit("name: PA01", "name: pa-1"), "pa-1", "a trajectory name is its family's capital letters");
  expect_read_error(edit("  - {name: PA01, posture: A, speed: 1, sequence: [{pattern: singles}]}",
                         "  - {name: PA01, posture: A, sequence: [{pattern: singles}]}"),
                    "  - {name: PA01", "a trajectory lacks the key 'speed'");
  expect_read_error(edit("postures:\n  A:", "postures:\n  A':"), "  A':", "may not end in '");
  // The parser notices the unclosed list where a mapping key appears inside it.
  expect_read_error(edit("limits:\n", "limits: [\n"),
                    "  velocity:", "YAML syntax error: end of sequence flow not found");
}

TEST_F(BrokenDesign, LimitViolationsAtBuildNameTrajectoryJointAndTime) {
  // Joint 7 swinging 175 deg around 0 passes its stop (-169.8 deg less the 2 deg margin).
  const std::string text =
      edit("amplitude: [45, 30, 45, 45, 60, 45, 90, 35]", "amplitude: [45, 30, 45, 45, 60, 45, 175, 35]");
  const auto d = TrajectoryDesign::read(write(text), crane_joints());
  EXPECT_NO_THROW(d.build("PA01"));  // PA01 does not move joint 7
  try {
    d.build("PA02");
    ADD_FAILURE() << "no limit error";
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.line(), line_of(text, "  - name: PA02"));
    EXPECT_NE(what.find("trajectory PA02: joint 7 (wrist_twist) reaches -175 deg"), std::string::npos) << what;
    EXPECT_NE(what.find(" at t = "), std::string::npos) << what;
  }
  EXPECT_THROW(d.build_all(), DataError);

  // Joint 7 at 6 rad/s and 100 rad/s^2 nominal: P7 at factor 0.9 cruises at 5.4 rad/s, over the
  // 4.8171 rad/s of the URDF.
  const std::string fast =
      edit("velocity: [2, 2, 2.5, 2.5, 3, 3, 3, 3]\n  acceleration: [10, 10, 15, 15, 20, 20, 20, 20]",
           "velocity: [2, 2, 2.5, 2.5, 3, 3, 6, 3]\n  acceleration: [10, 10, 15, 15, 20, 20, 100, 20]");
  const auto f = TrajectoryDesign::read(write(fast), crane_joints());
  try {
    f.build("PA02");
    ADD_FAILURE() << "no velocity error";
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(
        what.find(
            "trajectory PA02: joint 7 (wrist_twist) moves at 5.4 rad/s, over its velocity limit 4.8171 rad/s at t = "),
        std::string::npos)
        << what;
  }
  EXPECT_THROW(d.build("PA03"), DataError);  // not in the design
}

TEST_F(BrokenDesign, MissingFileIsAnError) {
  try {
    TrajectoryDesign::read(dir_ / "none.yaml", crane_joints());
    ADD_FAILURE();
  } catch (const DataError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos);
  }
}

}  // namespace
}  // namespace symoro::trajectory

// The Fourier excitation trajectory (trajectory/fourier.hpp): derivatives against central
// differences of q, at rest at the start and after each period once come_to_rest_at moved its
// coefficients, and the closed-form bounds above the maxima of a dense grid (equal for a single
// harmonic).

namespace symoro::trajectory {
namespace {

FourierTrajectory random_fourier(int n, int L, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  FourierTrajectory f;
  f.name = "F";
  f.w = 2 * 3.14159265358979323846 / 10;  // 10 s period
  f.q0 = Eigen::VectorXd::Zero(n);
  f.a.resize(n, L);
  f.b.resize(n, L);
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < L; ++l) {
      f.a(j, l) = 0.3 * u(gen);
      f.b(j, l) = 0.3 * u(gen);
    }
  return f;
}

TEST(FourierTrajectory, DerivativesRestAndBounds) {
  FourierTrajectory f = random_fourier(7, 5, 11);
  Eigen::VectorXd start(7);
  start << 0.1, -0.2, 0.3, -1.0, 0.5, 0.2, -0.3;
  f.come_to_rest_at(start);
  Eigen::VectorXd q, qd, qdd, qp, qdp, qddp, qm, qdm, qddm;
  for (const double t : {0.0, f.period()}) {
    f.evaluate(t, q, qd, qdd);
    EXPECT_LT((q - start).cwiseAbs().maxCoeff(), 1e-12) << t;
    EXPECT_LT(qd.cwiseAbs().maxCoeff(), 1e-12) << t;
    EXPECT_LT(qdd.cwiseAbs().maxCoeff(), 1e-12) << t;
  }
  const double h = 1e-5;
  for (const double t : {0.7, 3.1, 8.9}) {
    f.evaluate(t, q, qd, qdd);
    f.evaluate(t + h, qp, qdp, qddp);
    f.evaluate(t - h, qm, qdm, qddm);
    EXPECT_LT(((qp - qm) / (2 * h) - qd).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_LT(((qdp - qdm) / (2 * h) - qdd).cwiseAbs().maxCoeff(), 1e-8);
  }
  // A dense grid (1 ms over the period) never exceeds the bounds.
  const SampledReference r = f.sample(0.001);
  EXPECT_EQ(r.cycles(), 10001);
  const Eigen::VectorXd pb = f.position_bound(), vb = f.velocity_bound(), ab = f.acceleration_bound();
  for (int j = 0; j < 7; ++j) {
    EXPECT_LE((r.q.row(j).array() - f.q0(j)).abs().maxCoeff(), pb(j) + 1e-12);
    EXPECT_LE(r.qd.row(j).cwiseAbs().maxCoeff(), vb(j) + 1e-12);
    EXPECT_LE(r.qdd.row(j).cwiseAbs().maxCoeff(), ab(j) + 1e-12);
  }
  // One harmonic: each bound is reached (a rotating vector).
  FourierTrajectory one = random_fourier(2, 1, 3);
  const SampledReference s = one.sample(0.0005);
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(s.qd.row(j).cwiseAbs().maxCoeff(), one.velocity_bound()(j), 1e-6);
    EXPECT_NEAR(s.qdd.row(j).cwiseAbs().maxCoeff(), one.acceleration_bound()(j), 1e-6);
  }
}

}  // namespace
}  // namespace symoro::trajectory
