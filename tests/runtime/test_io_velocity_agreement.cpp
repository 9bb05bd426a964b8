// io::velocity_agreement and its plausibility check (import.hpp): a log's measured velocity
// integrated over its stamps against its position's change. Logs synthesized here from two
// robots' generated models (jittered stamps, 5 % stale rows, a 16-bit encoder and the
// controller's own velocity estimate, late by an 80 Hz low-pass),
// then given the mistakes users' exports have: stamps read one nominal period apart over a span
// 2 % short (the real Panda export read row by row), a velocity in deg/s beside radians, a
// continuous joint wrapped into (-pi, pi], a joint that never moves. Expected values by hand:
// 1 / 0.98, pi / 180.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "symoro/error.hpp"
#include "symoro/io/import.hpp"
#include "synthetic_log.hpp"

namespace symoro {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A controller's log of the synthesized motion: q from a 16-bit encoder, its velocity estimate
// late by a first-order 80 Hz low-pass; the stale rows repeat the row before.
template <class Model>
io::Log controller_log(unsigned seed) {
  const Eigen::Matrix<double, Model::np, 1> phi = Eigen::Matrix<double, Model::np, 1>::Constant(0.1);
  io::Log log = test::synthesize<Model>("run", phi, 12.0, seed, 0.05);
  const double lsb = 2 * kPi / 65536, a = std::exp(-2 * kPi * 80 * 0.001);
  Eigen::RowVectorXd v = log.qd.row(0);
  for (Eigen::Index i = 0; i < log.samples(); ++i) {
    if (i > 0 && log.time(i) > log.time(i - 1) && log.q.row(i) == log.q.row(i - 1) &&
        log.tau.row(i) == log.tau.row(i - 1)) {
      log.qd.row(i) = log.qd.row(i - 1);  // stale: the row before again
      continue;
    }
    v = a * v + (1 - a) * log.qd.row(i);
    log.qd.row(i) = v;
    log.q.row(i) = (log.q.row(i) / lsb).array().round().matrix() * lsb;
  }
  return log;
}

io::ImportedLog imported(io::Log log) {
  io::ImportedLog in;
  in.input = "export.csv";
  in.log = std::move(log);
  in.rows = static_cast<int>(in.log.samples());
  for (int i = 0; i < in.rows; ++i) in.lines.push_back(i + 2);
  return in;
}

io::ImportTarget target_of(const io::Log& log) {
  io::ImportTarget t;
  t.joints = log.meta.joints;
  return t;
}

template <class Model>
void agrees_on_its_stamps_and_finds_a_stretched_axis(unsigned seed) {
  const io::Log log = controller_log<Model>(seed);
  const io::VelocityAgreement a = io::velocity_agreement(log);
  EXPECT_EQ(a.window, 100);  // 0.1 s at 1 kHz
  for (int j = 0; j < Model::nq; ++j) {
    EXPECT_NEAR(a.scale(j), 1.0, 3e-3) << "joint " << j + 1;
    EXPECT_LT(a.mismatch(j), 0.05) << "joint " << j + 1;
  }
  EXPECT_NO_THROW(io::check_plausible(imported(log), {}, target_of(log)));

  // The stamps replaced by rows one nominal period apart over a span 2 % short: every joint's
  // position changes 1 / 0.98 times what its velocity integrates to.
  io::Log squeezed = log;
  for (Eigen::Index k = 0; k < log.samples(); ++k) squeezed.time(k) = log.time(0) + 0.98 * (log.time(k) - log.time(0));
  const io::VelocityAgreement b = io::velocity_agreement(squeezed);
  for (int j = 0; j < Model::nq; ++j) EXPECT_NEAR(b.scale(j), 1 / 0.98, 3e-3) << "joint " << j + 1;
  EXPECT_NO_THROW(io::check_plausible(imported(squeezed), {}, target_of(log)));  // a remark, not an error
}

TEST(VelocityAgreement, AgreesOnItsStampsAndFindsAStretchedAxisRx90) {
  agrees_on_its_stamps_and_finds_a_stretched_axis<rx90::Model>(3);
}
TEST(VelocityAgreement, AgreesOnItsStampsAndFindsAStretchedAxisCraneX7) {
  agrees_on_its_stamps_and_finds_a_stretched_axis<crane_x7::Model>(5);
}

// deg/s beside radians: scale pi / 180, refused naming the joint, the unit and the way out.
TEST(VelocityAgreement, AVelocityInDegreesPerSecondIsRefused) {
  io::Log log = controller_log<rx90::Model>(7);
  log.qd.col(2) *= 180 / kPi;
  const io::VelocityAgreement a = io::velocity_agreement(log);
  EXPECT_NEAR(a.scale(2), kPi / 180, 3e-3 * kPi / 180);
  EXPECT_NEAR(a.scale(1), 1.0, 3e-3);
  try {
    io::check_plausible(imported(log), {}, target_of(log));
    ADD_FAILURE() << "a velocity in deg/s was accepted";
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("export.csv"), std::string::npos) << what;
    EXPECT_NE(what.find("joint 3 '" + log.meta.joints[2] + "'"), std::string::npos) << what;
    EXPECT_NE(what.find("changes 0.017"), std::string::npos) << what;
    EXPECT_NE(what.find("rad/s"), std::string::npos) << what;
    EXPECT_NE(what.find("--allow-implausible"), std::string::npos) << what;
  }
  // A measured velocity the import differentiated itself is not judged.
  log.meta.velocity = io::Velocity::differentiated;
  EXPECT_NO_THROW(io::check_plausible(imported(log), {}, target_of(log)));
}

// A continuous joint logged wrapped into (-pi, pi] turning at 3 rad/s: the windows across a wrap
// are left out, the rest agree. A joint that never moves is not judged (NaN).
TEST(VelocityAgreement, WrapsAreLeftOutAndAStillJointIsNotJudged) {
  io::Log log = controller_log<crane_x7::Model>(9);
  for (Eigen::Index k = 0; k < log.samples(); ++k) {
    const double turned = 3.0 * (log.time(k) - log.time(0));
    log.q(k, 0) = std::remainder(turned, 2 * kPi);
    log.qd(k, 0) = 3.0;
    log.q(k, 4) = 0.25;
    log.qd(k, 4) = 0;
  }
  const io::VelocityAgreement a = io::velocity_agreement(log);
  EXPECT_NEAR(a.scale(0), 1.0, 1e-9);
  EXPECT_LT(a.mismatch(0), 1e-9);
  EXPECT_TRUE(std::isnan(a.scale(4)));
  EXPECT_LT(a.windows, static_cast<int>(log.samples() / 100));  // the wraps' windows left out
  EXPECT_NO_THROW(io::check_plausible(imported(log), {}, target_of(log)));
}

}  // namespace
}  // namespace symoro
