// identify::identification_model(handle, full) (identify/loaded_model.hpp), through a robot
// library loaded at run time and through the model linked in (identification_model<Model>(), the
// same implementation over the linked kernels), against a second implementation written in the
// generated Model's fixed sizes (generated_identification_model.hpp, what the runtime compiled per
// model before), on the CRANE-X7's reduced model (fixed parameters at nonzero CAD values, so the
// fixed torque and the held rows matter): the stacked regression, the open-loop torque, the state
// derivatives, the inertia function, the physical path and the closed loop with its sensitivities
// (under the experiment's controller on an excerpt of V01 at the twin's truth), all bit for bit.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include <symoro/crane_x7.hpp>

#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/loaded_closed_loop.hpp"
#include "symoro/identify/loaded_model.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/robot/load_robot.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

#include "generated_identification_model.hpp"

namespace symoro {
namespace {

using Full = crane_x7::Model;
using Reduced = crane_x7::reduced::Model;
constexpr int n = Full::nq;
const std::string kRobot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";

std::shared_ptr<const identify::IdentificationModel> loaded(const std::string& label) {
  robot::LoadOptions o;
  o.cache_dir = SYMORO_TEST_ROBOT_CACHE;
  const auto lib = robot::load_robot(kRobot, o);
  return identify::identification_model(lib->model(label), lib->model(0));
}

twin::TwinConfig ideal_config() {
  twin::TwinConfig c = twin::read_twin_config(kRobot + "/twin.yaml", n);
  c.effects.disable_all();
  return c;
}

Eigen::VectorXd reduced_truth() { return Reduced::from_parent(twin::make_truth(symoro::robot::compiled_model<Full>(), ideal_config()).phi); }

preprocess::Samples random_samples(int count, unsigned seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  preprocess::Samples s;
  for (auto* m : {&s.q, &s.qd, &s.qdd, &s.tau}) {
    m->resize(count, n);
    for (Eigen::Index i = 0; i < m->size(); ++i) m->data()[i] = u(g);
  }
  return s;
}

TEST(LoadedIdentificationModel, EqualsTheGeneratedModelsBitForBit) {
  const auto a = loaded("reduced");
  const auto b = identify::generated_identification_model<Reduced>();
  EXPECT_EQ(a->description().np, b->description().np);
  EXPECT_EQ(a->description().variant, "reduced");
  const preprocess::Samples s = random_samples(40, 7);
  const identify::Regression ra = a->stack_regression(s), rb = b->stack_regression(s);
  EXPECT_EQ(ra.W, rb.W);
  EXPECT_EQ(ra.y, rb.y);
  EXPECT_NE(ra.y, Eigen::Map<const Eigen::VectorXd>(s.tau.transpose().data(), s.tau.size()))  // a fixed torque
      << "the reduced model's fixed parameters should add a torque";
  const Eigen::VectorXd phi = reduced_truth();
  EXPECT_EQ(a->open_loop_torque(s, phi), b->open_loop_torque(s, phi));
  for (bool with_fixed : {true, false}) {
    identify::StateDerivatives da, db;
    a->state_derivatives(s.q.row(3).transpose(), s.qd.row(3).transpose(), s.qdd.row(3).transpose(), phi, with_fixed, da);
    b->state_derivatives(s.q.row(3).transpose(), s.qd.row(3).transpose(), s.qdd.row(3).transpose(), phi, with_fixed, db);
    EXPECT_EQ(da.tau, db.tau);
    EXPECT_EQ(da.dq, db.dq);
    EXPECT_EQ(da.dqd, db.dqd);
    EXPECT_EQ(da.dqdd, db.dqdd);
  }
  const auto ia = a->inertia_function(), ib = b->inertia_function();
  const Eigen::VectorXd q = s.q.row(5).transpose();
  Eigen::MatrixXd Ca, Cb, Ma, Mb;
  std::vector<Eigen::MatrixXd> La, Lb, dMa, dMb, d2Ma, d2Mb;
  ia->basis(q, Ca, La);
  ib->basis(q, Cb, Lb);
  EXPECT_EQ(Ca, Cb);
  EXPECT_EQ(La, Lb);
  ia->inertia_second_derivatives(q, phi, Ma, dMa, d2Ma);
  ib->inertia_second_derivatives(q, phi, Mb, dMb, d2Mb);
  EXPECT_EQ(Ma, Mb);
  EXPECT_EQ(dMa, dMb);
  EXPECT_EQ(d2Ma, d2Mb);

  // The physical path: the truth has a consistent set; a perturbed vector is projected the same.
  ASSERT_TRUE(a->supports_physical_consistency());
  EXPECT_EQ(a->physical_check(phi).ok(), b->physical_check(phi).ok());
  EXPECT_TRUE(a->physical_check(phi).ok());
  Eigen::VectorXd off = phi;
  off(0) -= 10 * std::abs(phi(0)) + 0.05;  // ZZR1 far below what a physical arm can have
  const Eigen::MatrixXd metric = (ra.W.transpose() * ra.W) / static_cast<double>(ra.W.rows()) +
                                 1e-6 * Eigen::MatrixXd::Identity(phi.size(), phi.size());
  const identify::PhysicalProjection pa = a->physical_projection(off, metric, 1e-7);
  const identify::PhysicalProjection pb = b->physical_projection(off, metric, 1e-7);
  EXPECT_EQ(pa.phi, pb.phi);
  EXPECT_EQ(pa.status, pb.status);
  EXPECT_EQ(pa.projected, pb.projected);
  EXPECT_EQ(a->consistency_target(phi), b->consistency_target(phi));
}

TEST(LoadedIdentificationModel, LinkedModelIsTheLoadedOneBitForBit) {
  const auto a = loaded("reduced");
  const auto c = identify::identification_model<Reduced>();
  EXPECT_EQ(c->description().variant, "reduced");
  const preprocess::Samples s = random_samples(30, 11);
  const identify::Regression ra = a->stack_regression(s), rc = c->stack_regression(s);
  EXPECT_EQ(ra.W, rc.W);
  EXPECT_EQ(ra.y, rc.y);
  EXPECT_EQ(a->open_loop_torque(s, reduced_truth()), c->open_loop_torque(s, reduced_truth()));
  EXPECT_EQ(a->parent_base_from_standard(twin::make_truth(symoro::robot::compiled_model<Full>(), ideal_config()).standard),
            c->parent_base_from_standard(twin::make_truth(symoro::robot::compiled_model<Full>(), ideal_config()).standard));
}

TEST(LoadedIdentificationModel, ClosedLoopEqualsTheFixedSizeSimulatorBitForBit) {
  const twin::TwinConfig config = ideal_config();
  const auto design = trajectory::TrajectoryDesign::read(kRobot + "/trajectories.yaml",
                                                         std::vector<JointInfo>(Full::joints.begin(), Full::joints.end()));
  trajectory::Trajectory v = design.build("V01"), cut = v;
  cut.segments.clear();
  for (const auto& seg : v.segments)
    if (seg.end() <= 3.2) cut.segments.push_back(seg);
  for (bool exact : {false, true}) {
    identify::ClosedLoopSetup setup = identify::closed_loop_setup(config.controller);
    setup.exact_sensitivities = exact;
    const auto reference = trajectory::sample(cut, setup.gains.period);
    const auto a = loaded("reduced")->closed_loop(setup, reference);
    const auto b = identify::generated_identification_model<Reduced>()->closed_loop(setup, reference);
    const auto c = identify::identification_model<Reduced>()->closed_loop(setup, reference);
    const Eigen::VectorXd phi = reduced_truth();
    preprocess::Channels ta, tb, da, db;
    identify::Divergence why;
    ASSERT_TRUE(a->simulate(phi, ta, &da, &why)) << why.describe();
    ASSERT_TRUE(b->simulate(phi, tb, &db, &why)) << why.describe();
    ASSERT_EQ(ta.rows(), tb.rows());
    ASSERT_GT(ta.rows(), 3000);
    EXPECT_EQ(ta, tb) << "exact " << exact << ": off by " << (ta - tb).cwiseAbs().maxCoeff();
    EXPECT_EQ(da, db) << "exact " << exact << ": off by " << (da - db).cwiseAbs().maxCoeff();
    EXPECT_GT(db.cwiseAbs().maxCoeff(), 0);
    preprocess::Channels tl, dl;
    ASSERT_TRUE(c->simulate(phi, tl, &dl, &why)) << why.describe();
    EXPECT_EQ(tl, ta);
    EXPECT_EQ(dl, da);
    // The run-time-size simulator (a robot of 1 or more than 8 joints) gives the same bits.
    robot::LoadOptions o;
    o.cache_dir = SYMORO_TEST_ROBOT_CACHE;
    const auto d = identify::detail::closed_loop_run_time_sizes(robot::load_robot(kRobot, o)->model("reduced"), setup,
                                                                reference);
    preprocess::Channels tr, dr;
    ASSERT_TRUE(d->simulate(phi, tr, &dr, &why)) << why.describe();
    EXPECT_EQ(tr, tb);
    EXPECT_EQ(dr, db);
    // Without sensitivities: the same plain simulation, which the default (frozen) sensitivities
    // leave as it is; exact ones step the state through the derivatives' own qdd.
    preprocess::Channels tc, tp;
    ASSERT_TRUE(a->simulate(phi, tc, nullptr, &why));
    ASSERT_TRUE(b->simulate(phi, tp, nullptr, &why));
    EXPECT_EQ(tc, tp);
    if (!exact) EXPECT_EQ(tc, tb);
    else EXPECT_LE((tc - tb).cwiseAbs().maxCoeff(), 1e-9 * tb.cwiseAbs().maxCoeff());
  }
}

}  // namespace
}  // namespace symoro
