// Physically consistent standard parameters from a base vector (identify/physical_consistency.hpp).
// Every claim is checked independently of the solver: pseudo-inertias rebuilt here from the
// parameter names and their eigenvalues from Eigen, B s from the generated base_from_standard.
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>

#include "symoro/identify/physical_consistency.hpp"
#include "symoro/identify/detail/physical_consistency_model.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "consistency_test_support.hpp"
#include "test_support.hpp"

namespace {

using Eigen::VectorXd;
using symoro::identify::ConsistencyOptions;
using symoro::identify::ConsistencyResult;
using symoro::identify::ConsistencyStatus;
using Crane = symoro::crane_x7::Model;
using Reduced = symoro::crane_x7::reduced::Model;
using Rx90 = symoro::rx90::Model;
using Rrp = symoro::stanford_rrp::Model;
using symoro::test::base_of;
using symoro::test::diagonal_consistent_standard;
using symoro::test::expect_consistent;
using symoro::test::perturbed;
using symoro::test::pseudo_inertia_by_name;
using symoro::test::smallest_drive_parameter;
using symoro::test::smallest_link_eigenvalue;

// Random consistent s -> phi = B s -> recovered from a prior 30 % off: consistent, and back onto
// phi to 1e-10.
template <class Model>
void round_trip(const VectorXd& truth, unsigned seed, double margin) {
  ASSERT_GE(smallest_link_eigenvalue<Model>(truth), margin) << "the drawn truth itself misses the margin";
  const VectorXd phi = base_of<Model>(truth);
  ConsistencyOptions o;
  o.margin = margin;
  const ConsistencyResult r =
      symoro::identify::consistent_standard_parameters<Model>(phi, perturbed(truth, 0.3, seed), o);
  expect_consistent<Model>(r, phi, margin);
}

TEST(PhysicalConsistency, PseudoInertiaMatchesTheDefinition) {
  symoro::test::Random rng(3);
  const VectorXd s = symoro::test::random_standard_parameters<Crane>(rng).s;
  const auto st = symoro::identify::consistency_structure<Crane>();
  ASSERT_EQ(st.links.size(), 7u);  // the hand joint carries no link
  ASSERT_EQ(st.B.rows(), Crane::np);
  EXPECT_LE((st.B * s - base_of<Crane>(s)).cwiseAbs().maxCoeff(), 1e-14);
  for (const auto& l : st.links)
    EXPECT_LE((symoro::identify::pseudo_inertia(s, l) - pseudo_inertia_by_name<Crane>(s, l.link)).norm(), 1e-15);
}

TEST(PhysicalConsistency, RandomConsistentRoundTripCraneX7) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    symoro::test::Random rng(seed);
    round_trip<Crane>(symoro::test::random_standard_parameters<Crane>(rng).s, 100 + seed, 1e-6);
  }
}

TEST(PhysicalConsistency, RandomConsistentRoundTripCraneX7Reduced) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    symoro::test::Random rng(seed);
    round_trip<Reduced>(diagonal_consistent_standard<Reduced>(rng), 200 + seed, 1e-6);
  }
}

TEST(PhysicalConsistency, RandomConsistentRoundTripRx90) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    symoro::test::Random rng(seed);
    round_trip<Rx90>(symoro::test::random_standard_parameters<Rx90>(rng).s, 300 + seed, 1e-6);
  }
}

TEST(PhysicalConsistency, RandomConsistentRoundTripStanfordRrp) {  // a prismatic joint
  for (unsigned seed = 1; seed <= 3; ++seed) {
    symoro::test::Random rng(seed);
    round_trip<Rrp>(symoro::test::random_standard_parameters<Rrp>(rng).s, 400 + seed, 1e-6);
  }
}

// A prior that is itself far from consistent (first moments 3x, masses 0.2x): the SDP must work.
TEST(PhysicalConsistency, InconsistentPriorRx90) {
  symoro::test::Random rng(11);
  const VectorXd truth = symoro::test::random_standard_parameters<Rx90>(rng).s;
  VectorXd prior = truth;
  for (int k = 0; k < Rx90::ns; ++k) {
    const std::string f = Rx90::standard_parameters[static_cast<std::size_t>(k)].family;
    if (f == "MX" || f == "MY" || f == "MZ") prior(k) *= 3;
    if (f == "M") prior(k) *= 0.2;
  }
  ASSERT_LT(smallest_link_eigenvalue<Rx90>(prior), 0);
  const VectorXd phi = base_of<Rx90>(truth);
  const ConsistencyResult r = symoro::identify::consistent_standard_parameters<Rx90>(phi, prior);
  expect_consistent<Rx90>(r, phi, 0);
  EXPECT_GT(r.solves, 0);
}

// The twin's CAD truth (robots/crane_x7/twin.yaml in the model's frames): with the CAD values
// as the prior it comes back unchanged; from a prior 30 % off, a consistent set equivalent to it
// (the same base vector), with the entries B fixes on their own (FV, IA3..8, MX, ZZ7 ...) equal.
TEST(PhysicalConsistency, CraneX7TwinTruth) {
  const auto config = symoro::twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Crane::nq);
  const VectorXd truth = symoro::twin::make_truth(symoro::robot::compiled_model<Crane>(), config).standard;
  const VectorXd phi = base_of<Crane>(truth);
  ASSERT_GT(smallest_link_eigenvalue<Crane>(truth), 0);

  const ConsistencyResult same = symoro::identify::consistent_standard_parameters<Crane>(phi, truth);
  expect_consistent<Crane>(same, phi, 0);
  EXPECT_LE((same.s - truth).cwiseAbs().maxCoeff(), 1e-12);

  const ConsistencyResult r = symoro::identify::consistent_standard_parameters<Crane>(phi, perturbed(truth, 0.3, 7));
  expect_consistent<Crane>(r, phi, 0);
  const auto st = symoro::identify::consistency_structure<Crane>();
  int alone = 0;
  for (int k = 0; k < Crane::ns; ++k) {
    // s_k is identifiable on its own when e_k is in B's row space.
    const VectorXd e = VectorXd::Unit(Crane::ns, k);
    const VectorXd x = st.B.transpose().colPivHouseholderQr().solve(e);
    if ((st.B.transpose() * x - e).norm() > 1e-9) continue;
    ++alone;
    EXPECT_NEAR(r.s(k), truth(k), 1e-10 * std::max(1.0, std::abs(truth(k)))) << Crane::standard_parameters[k].name;
  }
  EXPECT_GT(alone, 20);
}

// A random consistent CRANE-X7 truth and its base vector with ZZ7 made negative: no consistent set
// maps onto it (ZZ7, a base parameter on its own, is a link's inertia about its axis).
struct InfeasibleCrane {
  symoro::test::Random rng;  // continues after the truth's draws
  VectorXd truth, phi;
  explicit InfeasibleCrane(unsigned seed) : rng(seed) {
    truth = symoro::test::random_standard_parameters<Crane>(rng).s;
    phi = base_of<Crane>(truth);
    phi(symoro::crane_x7::param::ZZ7) = -0.01;
  }
};

// A base vector no consistent set maps onto: ZZ7 (the last link's inertia about its z axis,
// a base parameter on its own) negative. Reported with the nearest base vector that has one,
// which is itself solvable; phi is not forced.
TEST(PhysicalConsistency, InfeasibleBaseVectorIsReported) {
  const InfeasibleCrane c(5);
  const VectorXd& truth = c.truth;
  const VectorXd& phi = c.phi;
  const ConsistencyResult r = symoro::identify::consistent_standard_parameters<Crane>(phi, truth);
  ASSERT_EQ(r.status, ConsistencyStatus::NoConsistentSet) << r.message;
  std::printf("  %s\n  phase 1 t = %.3g, %d CSDP solves, %.3f s\n", r.message.c_str(), r.feasibility, r.solves, r.wall);
  EXPECT_LT(r.feasibility, 0);
  ASSERT_EQ(r.phi_consistent.size(), Crane::np);
  EXPECT_GT(r.base_distance, 0);
  // phi_c = B s_c with s_c consistent, checked here.
  EXPECT_LE((base_of<Crane>(r.s) - r.phi_consistent).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GE(smallest_link_eigenvalue<Crane>(r.s), -1e-12);
  EXPECT_GE(r.phi_consistent(symoro::crane_x7::param::ZZ7), 0);
  // Nearest: no farther than the truth's base vector (phi with ZZ7 put back; bound within the
  // solver's regularization towards the prior), in the documented default metric rebuilt here.
  const auto st = symoro::identify::consistency_structure<Crane>();
  const VectorXd scale = symoro::identify::default_consistency_weights(st, truth).cwiseInverse();
  const int zz7 = symoro::crane_x7::param::ZZ7;
  const double wb = 1 / (st.B.row(zz7) * scale.asDiagonal()).norm();
  const double via_truth = wb * std::abs(base_of<Crane>(truth)(zz7) - phi(zz7));
  std::printf("  distance %.6g, via the truth %.6g\n", r.base_distance, via_truth);
  EXPECT_LE(r.base_distance, via_truth * (1 + 1e-4));
  EXPECT_GE(r.base_distance, wb * 0.01);  // ZZ7 >= 0 for every consistent set
  // The change is where phi was impossible: the other identifiable-alone entries barely move.
  EXPECT_NEAR(r.phi_consistent(symoro::crane_x7::param::FV3), phi(symoro::crane_x7::param::FV3), 1e-6);
  // phi_c admits a consistent set: solved again, consistent and mapping onto it.
  const ConsistencyResult again = symoro::identify::consistent_standard_parameters<Crane>(r.phi_consistent, truth);
  expect_consistent<Crane>(again, r.phi_consistent, 0);
}

// The nearest consistent base vector in a full metric (base_metric_root R, e.g. a regression's
// R factor: the predicted torque): its distance is |R (phi_c - phi)|, and it is no farther in R's
// metric than the default metric's answer (and that one no farther in the default metric).
TEST(PhysicalConsistency, InfeasibleBaseVectorInAFullMetric) {
  InfeasibleCrane c(7);
  const VectorXd& truth = c.truth;
  const VectorXd& phi = c.phi;
  symoro::test::Random& rng = c.rng;
  const ConsistencyResult d = symoro::identify::consistent_standard_parameters<Crane>(phi, truth);
  ASSERT_EQ(d.status, ConsistencyStatus::NoConsistentSet) << d.message;
  // A random well-conditioned R, rows coupling every base parameter.
  Eigen::MatrixXd R = Eigen::MatrixXd::Identity(Crane::np, Crane::np);
  for (int i = 0; i < Crane::np; ++i)
    for (int j = 0; j < Crane::np; ++j) R(i, j) += 0.3 * rng.uniform(-1, 1);
  symoro::identify::ConsistencyOptions o;
  o.base_metric_root = R;
  const ConsistencyResult m = symoro::identify::consistent_standard_parameters<Crane>(phi, truth, o);
  ASSERT_EQ(m.status, ConsistencyStatus::NoConsistentSet) << m.message;
  EXPECT_NEAR(m.base_distance, (R * (m.phi_consistent - phi)).norm(), 1e-12 * (1 + m.base_distance));
  EXPECT_LE((base_of<Crane>(m.s) - m.phi_consistent).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GE(smallest_link_eigenvalue<Crane>(m.s), -1e-12);
  const double in_r_default = (R * (d.phi_consistent - phi)).norm();
  std::printf("  R metric: its answer %.6g, the default metric's answer %.6g\n", m.base_distance, in_r_default);
  EXPECT_LE(m.base_distance, in_r_default * (1 + 1e-4));
  const ConsistencyResult again = symoro::identify::consistent_standard_parameters<Crane>(m.phi_consistent, truth);
  expect_consistent<Crane>(again, m.phi_consistent, 0);
  o.base_metric_root = Eigen::MatrixXd::Identity(3, 4);
  EXPECT_THROW(symoro::identify::consistent_standard_parameters<Crane>(phi, truth, o), std::invalid_argument);
}

// Held rows: the nearest consistent vector that keeps chosen entries of phi exactly (what the
// study's projection of a variant needs for its fixed parameters). Hold the entry, other than the
// infeasible one, that the free answer moved most: it stays bit for bit, the answer is consistent
// and no nearer than the free one.
TEST(PhysicalConsistency, HeldRowsStayExactly) {
  const InfeasibleCrane c(9);
  const VectorXd& truth = c.truth;
  const VectorXd& phi = c.phi;
  const int zz7 = symoro::crane_x7::param::ZZ7;
  const ConsistencyResult free = symoro::identify::consistent_standard_parameters<Crane>(phi, truth);
  ASSERT_EQ(free.status, ConsistencyStatus::NoConsistentSet) << free.message;
  VectorXd moved = (free.phi_consistent - phi).cwiseAbs();
  moved(zz7) = 0;
  Eigen::Index row = 0;
  const double most = moved.maxCoeff(&row);
  std::printf("  the free answer moves %s by %.3g\n", Crane::parameters[static_cast<std::size_t>(row)].name, most);
  ASSERT_GT(most, 1e-6);
  ConsistencyOptions o;
  o.held_rows = {static_cast<int>(row)};
  const ConsistencyResult held = symoro::identify::consistent_standard_parameters<Crane>(phi, truth, o);
  ASSERT_EQ(held.status, ConsistencyStatus::NoConsistentSet) << held.message;
  ASSERT_EQ(held.phi_consistent.size(), Crane::np);
  EXPECT_LE(std::abs(held.phi_consistent(row) - phi(row)), 1e-12 * std::max(1.0, std::abs(phi(row))));
  EXPECT_GE(held.base_distance, free.base_distance * (1 - 1e-6));
  EXPECT_LE((base_of<Crane>(held.s) - held.phi_consistent).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GE(smallest_link_eigenvalue<Crane>(held.s), -1e-12);
  std::printf("  held: distance %.6g (free %.6g)\n", held.base_distance, free.base_distance);
  o.held_rows = {Crane::np};
  EXPECT_THROW(symoro::identify::consistent_standard_parameters<Crane>(phi, truth, o), std::invalid_argument);
}

// A parameter B fixes on its own out of its bounds (FV3 < 0): no set, and the message says which.
TEST(PhysicalConsistency, FixedParameterOutOfBounds) {
  symoro::test::Random rng(6);
  const VectorXd truth = symoro::test::random_standard_parameters<Crane>(rng).s;
  VectorXd phi = base_of<Crane>(truth);
  phi(symoro::crane_x7::param::FV3) = -0.1;
  const ConsistencyResult r = symoro::identify::consistent_standard_parameters<Crane>(phi, truth);
  ASSERT_EQ(r.status, ConsistencyStatus::NoConsistentSet) << r.message;
  EXPECT_NE(r.message.find("FV3"), std::string::npos) << r.message;
  ASSERT_EQ(r.phi_consistent.size(), Crane::np);
  EXPECT_NEAR(r.phi_consistent(symoro::crane_x7::param::FV3), 0, 1e-6);
  EXPECT_GE(r.phi_consistent(symoro::crane_x7::param::FV3), -1e-12);
}

TEST(PhysicalConsistency, RejectsBadInput) {
  const auto st = symoro::identify::consistency_structure<Crane>();
  EXPECT_THROW(symoro::identify::consistent_standard_parameters(st, VectorXd::Zero(3), VectorXd::Zero(Crane::ns)),
               std::invalid_argument);
  ConsistencyOptions o;
  o.margin = -1;
  EXPECT_THROW(
      symoro::identify::consistent_standard_parameters(st, VectorXd::Zero(Crane::np), VectorXd::Zero(Crane::ns), o),
      std::invalid_argument);
}

}  // namespace
