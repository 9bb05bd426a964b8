// Shared by the payload tests (test_payload.cpp, payload_tare_cases.cpp, one program): a wrist
// motion, the targets' errors, and the CRANE-X7 twin carrying a payload on top of an arm
// identified from its own runs.
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "independent_arm.hpp"
#include "independent_rx90.hpp"

#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/least_squares.hpp"
#include "symoro/payload/payload_identification.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/study/options.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::test::payload_support {

using Crane = crane_x7::Model;

// The wrist moves, the rest holds `pose`: on each of `count` joints from index `first`, three
// sines (0.23, 0.61, 1.13 Hz x a joint factor) of `amplitude` rad in all, faded in and out over 1 s.
inline trajectory::SampledReference wrist_reference(const Eigen::VectorXd& pose, int first, int count, double amplitude,
                                                    double seconds) {
  const int n = static_cast<int>(pose.size());
  trajectory::SampledReference ref;
  ref.name = "wrist";
  ref.period = 0.001;
  const int K = static_cast<int>(seconds / ref.period) + 1;
  ref.q = pose.replicate(1, K);
  ref.qd = ref.qdd = Eigen::MatrixXd::Zero(n, K);
  const double f[3] = {0.23, 0.61, 1.13}, fade = 1.0;
  for (int k = 0; k < K; ++k) {
    const double t = k * ref.period, left = seconds - t;
    // s(t) = sin^2 (pi t / 2 fade) at either end, 1 between: q, qd, qdd by the product rule.
    double s = 1, sd = 0, sdd = 0;
    const double edge = std::min(t, left), sign = t < left ? 1 : -1, w = M_PI / (2 * fade);
    if (edge < fade) {
      s = std::pow(std::sin(w * edge), 2);
      sd = sign * w * std::sin(2 * w * edge);
      sdd = 2 * w * w * std::cos(2 * w * edge);
    }
    for (int m = 0; m < count; ++m) {
      const int j = first + m;
      double g = 0, gd = 0, gdd = 0;
      for (int h = 0; h < 3; ++h) {
        const double om = 2 * M_PI * f[h] * (1 + 0.17 * m), a = amplitude / 3, ph = 0.7 * h + 1.3 * m;
        g += a * std::sin(om * t + ph);
        gd += a * om * std::cos(om * t + ph);
        gdd -= a * om * om * std::sin(om * t + ph);
      }
      ref.q(j, k) = pose(j) + s * g;
      ref.qd(j, k) = sd * g + s * gd;
      ref.qdd(j, k) = sdd * g + 2 * sd * gd + s * gdd;
    }
  }
  return ref;
}

struct Errors {
  double mass, com, inertia;  // relative, m, relative (Frobenius)
};

inline Errors errors(const symoro::payload::PayloadInertial& e, const symoro::payload::PayloadInertial& truth) {
  return {std::abs(e.mass - truth.mass) / truth.mass, (e.com - truth.com).norm(),
          (e.inertia - truth.inertia).norm() / truth.inertia.norm()};
}

inline void report(const char* what, const symoro::payload::PayloadEstimate& e, const Errors& err) {
  std::printf(
      "%s: mass %.4f kg (sd %.4f), com [%.4f %.4f %.4f] m, inertia diag [%.3g %.3g %.3g]: errors mass "
      "%.2f %%, com %.2f mm, inertia %.1f %%; lags %d, condition %.3g, projected %d\n",
      what, e.payload.mass, e.mass_std, e.payload.com.x(), e.payload.com.y(), e.payload.com.z(),
      e.payload.inertia(0, 0), e.payload.inertia(1, 1), e.payload.inertia(2, 2), 100 * err.mass, 1000 * err.com,
      100 * err.inertia, e.lags, e.condition, e.projected ? 1 : 0);
}

// The targets: mass within 2 %, CoM within 3 mm, inertia within 15 %.
inline Errors expect_within_targets(const symoro::payload::PayloadEstimate& e,
                                    const symoro::payload::PayloadInertial& truth, const char* what) {
  const Errors err = errors(e.payload, truth);
  report(what, e, err);
  EXPECT_LT(err.mass, 0.02) << what;
  EXPECT_LT(err.com, 0.003) << what;
  EXPECT_LT(err.inertia, 0.15) << what;
  return err;
}

// A regression stacked from several logs' samples at the study's preprocessing.
template <class Model>
inline identify::Regression stacked(const identify::IdentificationModel& model, const std::vector<io::Log>& logs) {
  identify::Regression all;
  all.joints = Model::nq;
  for (const io::Log& log : logs) {
    const identify::Regression r =
        model.stack_regression(preprocess::preprocess(log, 0.010, study::StudyOptions{}.preprocess));
    all.W.conservativeResize(all.W.rows() + r.W.rows(), r.W.cols());
    all.W.bottomRows(r.W.rows()) = r.W;
    all.y.conservativeResize(all.y.size() + r.y.size());
    all.y.tail(r.y.size()) = r.y;
    all.samples += r.samples;
  }
  return all;
}

// The CRANE-X7 twin's arm as a user's identification knows it: the full model's least squares on
// four 30 s runs of joints 1-7 without the payload. Identified, not the twin's truth, because of
// the logs' timing: the current logged at a stamp was commanded one cycle earlier and has driven
// the links since that command arrived (d = 0.9 ms after the earlier stamp, T = 1 ms), so it leads
// the torque that moved the links by d - T/2 = 0.4 ms. The arm's identification takes that lead
// into its rotor inertias (IA_j + 0.4 ms x FV_j, checked below), and a payload fitted on top of it
// sees none; on the twin's truth the wrist's viscous friction would show as payload inertia (Izz
// 5 % high, xx and yy 10 %).
inline const identify::LeastSquaresResult& crane_arm_fit() {
  static const identify::LeastSquaresResult fit = [] {
    const twin::TwinConfig arm =
        twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Crane::nq);
    std::vector<io::Log> logs;
    for (unsigned seed : {61u, 62u, 63u, 64u}) {
      twin::RunOptions o;
      o.robot = "crane_x7";
      o.seed = seed;
      Eigen::VectorXd pose(Crane::nq);
      pose << 0.2 * (seed - 62.0), 0.3, 0.1, -1.2, 0.1 * (seed - 62.0), 0.3, 0, 0;
      logs.push_back(twin::ClosedLoopTwin(robot::compiled_model<Crane>(), arm)
                         .run(wrist_reference(pose, 0, 7, 0.9 + 0.1 * (seed % 3), 30), o));
    }
    return identify::least_squares(stacked<Crane>(*identify::identification_model<Crane>(), logs), {true});
  }();
  return fit;
}
inline const Eigen::VectorXd& crane_arm_identified() { return crane_arm_fit().phi; }

// The twin carrying a 0.35 kg body (about a 6 x 4 x 10 cm box) off the flange's axis, its
// inertia turned about z, at twin.yaml's noise, jitter, dropped samples and bus delay.
struct CranePayloadTwin {
  twin::TwinConfig with;
  symoro::payload::PayloadInertial truth;
  trajectory::SampledReference wrist;  // joints 5-7 for 20 s (joint 8, the hand, carries nothing)
};
inline CranePayloadTwin crane_payload_twin() {
  const auto override_file = std::filesystem::temp_directory_path() / "payload_twin.yaml";
  std::ofstream(override_file) << "effects:\n  payload: {enabled: true, mass: 0.35, com: [0.012, -0.008, 0.06], "
                                  "inertia: [1.7e-4, 2.0e-5, 0, 2.0e-4, 0, 1.5e-4]}\n";
  CranePayloadTwin t;
  t.with = twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Crane::nq, override_file);
  std::filesystem::remove(override_file);
  t.truth.mass = 0.35;
  t.truth.com = {0.012, -0.008, 0.06};
  t.truth.inertia << 1.7e-4, 2.0e-5, 0, 2.0e-5, 2.0e-4, 0, 0, 0, 1.5e-4;
  Eigen::VectorXd pose(Crane::nq);
  pose << 0.3, 0.6, 0, -1.4, 0, 0, 0, 0;
  t.wrist = wrist_reference(pose, 4, 3, 1.2, 20);
  return t;
}

inline io::Log crane_run(const twin::TwinConfig& c, const trajectory::SampledReference& ref, unsigned seed) {
  twin::RunOptions o;
  o.robot = "crane_x7";
  o.seed = seed;
  return twin::ClosedLoopTwin(robot::compiled_model<Crane>(), c).run(ref, o);
}

// The arm `arm` carrying a rigid body on its last link, as one more inertial of its chain (the
// independent arm takes no effects).
inline twin::TwinConfig carrying(const twin::TwinConfig& arm, const symoro::payload::PayloadInertial& b) {
  twin::TwinConfig tool = arm;
  twin::UrdfInertial body;
  body.name = "tool";
  body.on = tool.chain.joints.back().name;
  body.mass = b.mass;
  body.com = b.com;
  body.inertia = b.inertia;
  tool.chain.inertials.push_back(body);
  return tool;
}

// The independent RX-90 identified without a tool: least squares on its full model from two 20 s
// runs of all joints (seeds 61 and 62).
inline Eigen::VectorXd rx90_arm_identified(const twin::TwinConfig& arm) {
  const auto model = identify::identification_model<rx90::Model>();
  test::IndependentArmOptions io;
  std::vector<io::Log> logs;
  for (unsigned seed : {61u, 62u}) {
    io.seed = seed;
    logs.push_back(test::run_independent_arm<rx90::Model>(arm, test::rx90_reference("arm", 20, seed), io));
  }
  return identify::least_squares(stacked<rx90::Model>(*model, logs), {true}).phi;
}

}  // namespace symoro::test::payload_support
