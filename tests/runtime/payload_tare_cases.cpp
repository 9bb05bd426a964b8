// Payload identification with tare logs (identify_payload's second form; part of the test_payload
// program): an arm whose parameters of the payload's link are off by about what the main job's
// study leaves there puts the payload's inertia far off; a run of the same motion without the
// payload measures that error and takes it out. On the CRANE-X7 twin and on the independent
// RX-90 (independent_arm.hpp: its own integrator, loop and sensors).
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "independent_arm.hpp"
#include "independent_rx90.hpp"
#include "payload_test_support.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/least_squares.hpp"
#include "symoro/payload/payload_identification.hpp"

namespace {

using namespace symoro;
using namespace symoro::test::payload_support;
using Rx = rx90::Model;

// An error of the arm's parameters along the payload's (XX XY XZ YY YZ ZZ MX MY MZ M of its link),
// `scale` times the one dynid payload reads on the main job's CRANE-X7 study arm from a run
// without a payload (inertia about the CoM 6e-5, 3e-5, 4e-5 kg m^2, a third of a 0.35 kg body's).
payload::StandardVector arm_error(double scale) {
  payload::StandardVector e;
  e << 6e-5, 5e-6, -4e-6, 3e-5, 6e-6, 4e-5, 2e-4, -1e-4, 3e-4, 2e-3;
  return scale * e;
}

// The tare's two properties: the payload does not depend on the arm's error along its
// parameters (the error moves the tare's delta alone, exactly: the model is linear in both), and
// the tare measures that error (delta = -error, less the arm's own small one).
void expect_tare_takes_it_out(const std::vector<io::Log>& loaded, const std::vector<io::Log>& tare,
                              const identify::IdentificationModel& model, const Eigen::VectorXd& phi,
                              const payload::StandardVector& error, const payload::PayloadInertial& truth,
                              const char* robot) {
  const Eigen::VectorXd off = phi + payload::payload_link(model).map * error;
  const std::string name = robot;
  const Errors blind = errors(payload::identify_payload(loaded, model, off, model).payload, truth);
  report((name + ", the arm off, no tare").c_str(), payload::identify_payload(loaded, model, off, model), blind);
  EXPECT_GT(blind.inertia, 0.15) << robot;  // outside the target: 21 % and 25 % measured
  const payload::PayloadEstimate good = payload::identify_payload(loaded, tare, model, phi, model);
  const payload::PayloadEstimate e = payload::identify_payload(loaded, tare, model, off, model);
  expect_within_targets(e, truth, (name + ", the arm off, tared").c_str());
  EXPECT_LT((e.standard - good.standard).norm(), 1e-9 * good.standard.norm()) << robot;
  EXPECT_LT((e.tare - good.tare + error).head<6>().norm(), 1e-9 * error.head<6>().norm()) << robot;
  std::printf("%s: tare's inertia [%.3g %.3g %.3g %.3g %.3g %.3g] against the error's [%.3g %.3g %.3g ...]\n", robot,
              e.tare(0), e.tare(1), e.tare(2), e.tare(3), e.tare(4), e.tare(5), error(0), error(1), error(2));
  EXPECT_LT((e.tare + error).head<6>().norm(), 0.25 * error.head<6>().norm()) << robot;
  EXPECT_GT(e.tare_samples, 0);
  // With the known mass and with the instruments too.
  payload::PayloadOptions known, iv;
  known.mass = truth.mass;
  iv.reference_instruments = true;
  expect_within_targets(payload::identify_payload(loaded, tare, model, off, model, known), truth,
                        (name + ", the arm off, tared, known mass").c_str());
  if (loaded.front().has_references())
    expect_within_targets(payload::identify_payload(loaded, tare, model, off, model, iv), truth,
                          (name + ", the arm off, tared, instruments").c_str());
}

TEST(PayloadTare, ARunWithoutThePayloadTakesTheArmsErrorOutOfTheTwinsPayload) {
  const CranePayloadTwin t = crane_payload_twin();
  twin::TwinConfig bare = t.with;
  bare.effects.payload = false;
  const auto model = identify::identification_model<Crane>();
  expect_tare_takes_it_out({crane_run(t.with, t.wrist, 41)}, {crane_run(bare, t.wrist, 141)}, *model,
                           crane_arm_identified(), arm_error(1), t.truth, "crane_x7 twin");
}

TEST(PayloadTare, ARunWithoutTheToolTakesTheArmsErrorOutOfTheIndependentRx90sTool) {
  // The RX-90 of test_payload.cpp's tool test: the arm identified from two runs, a 5 kg tool.
  const twin::TwinConfig arm = test::rx90_twin();
  payload::PayloadInertial truth;
  truth.mass = 5;
  truth.com = {0.02, -0.015, 0.1};
  truth.inertia = Eigen::Vector3d(0.02, 0.018, 0.01).asDiagonal();
  const twin::TwinConfig tool = carrying(arm, truth);
  const auto model = identify::identification_model<Rx>();
  const Eigen::VectorXd phi = rx90_arm_identified(arm);
  test::IndependentArmOptions io;
  Eigen::VectorXd pose(Rx::nq);
  pose << 0.2, -0.5, 0.8, 0, 0, 0;
  const trajectory::SampledReference wrist = wrist_reference(pose, 3, 3, 1.5, 20);
  io.seed = 65;
  const io::Log loaded = test::run_independent_arm<Rx>(tool, wrist, io);
  io.seed = 66;
  const io::Log tare = test::run_independent_arm<Rx>(arm, wrist, io);
  // The error scaled to this tool (its inertia about the CoM is 100 times the CRANE-X7 body's).
  expect_tare_takes_it_out({loaded}, {tare}, *model, phi, arm_error(150), truth, "rx90 independent");
}

}  // namespace
