// The solvers behind the study give the same results after the histories that used to change
// them, whatever the heap looks like and whichever thread calls them: the all-pose audit (Ipopt,
// MUMPS) and the SDP projection (CSDP, BLAS) on CRANE-X7 and the RX-90, called again after
// audits and projections of other vectors and runs, after allocations that shift every later
// malloc's address, from another thread, and while another thread uses the same solvers.
// (Ipopt with MUMPS keeps state from one solve to the next: a study's SDP vectors depended on
// which runs its thread had done, and CLIE amplified the difference; pd_audit.cpp puts the
// audit's poses on a grid.) Compared to 1e-9; the bit-identical count is printed.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "symoro/identify/identification_model.hpp"  // inertia functions from symoro::<robot>_identification
#include "symoro/identify/least_squares.hpp"
#include "symoro/identify/regression.hpp"
#include "symoro/io/log.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "test_support.hpp"
#include "twin_dataset.hpp"

namespace {

using namespace symoro::identify;

// Bit for bit is the aim, but not guaranteed: a few results still differ by ~1e-13 between
// processes (docs/identification.md, Reproducibility), so the checks are to 1e-9 relative --
// far below anything a study's decisions see, far above those last bits -- and the bit-identical
// count is printed.
int identical = 0, compared = 0;
void same(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const char* what) {
  ++compared;
  identical += a == b;
  EXPECT_LE((a - b).norm(), 1e-9 * std::max(1.0, b.norm())) << what;
}
void same(double a, double b, const char* what) {
  ++compared;
  identical += a == b;
  EXPECT_NEAR(a, b, 1e-9 * std::max(1.0, std::abs(b))) << what;
}

struct Outcome {
  AuditResult audit;
  ProjectionResult projection;
};

// Blocks of 8 to 120 bytes kept alive, so that later allocations land elsewhere.
std::vector<std::unique_ptr<char[]>> shift_heap(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::unique_ptr<char[]>> keep;
  for (int i = 0; i < 37; ++i) keep.emplace_back(new char[8 * (1 + rng() % 15)]);
  return keep;
}

template <class Model>
void same_bits_whatever_the_heap(const Eigen::VectorXd& truth, const Eigen::VectorXd& direction) {
  const auto m = identification_model<Model>()->inertia_function();
  const AuditDomain domain = audit_domain<Model>();
  Eigen::VectorXd phi0 = truth;
  for (double t = 0.05; audit_pd(*m, phi0, domain).positive_definite(); t *= 1.5) phi0 = truth + t * direction;
  ProjectionOptions po;
  po.shortfall_raise = 0.5;
  auto solve = [&] {
    Outcome o;
    o.audit = audit_pd(*m, phi0, domain);
    o.projection = project_pd(*m, phi0, domain, po);
    return o;
  };
  const Outcome first = solve();
  ASSERT_TRUE(first.projection.feasible) << first.projection.status;
  std::vector<Outcome> again;
  // After audits of other vectors (each may leave state in the solvers' libraries).
  for (double scale : {1.3, 0.7, -1.0}) {
    audit_pd(*m, scale * first.projection.phi, domain);
    again.push_back(solve());
  }
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto keep = shift_heap(seed);
    again.push_back(solve());
  }
  std::thread([&] {
    const auto keep = shift_heap(4);
    again.push_back(solve());
  }).join();
  for (const Outcome& o : again) {
    same(o.audit.lambda_min, first.audit.lambda_min, "audit lambda_min");
    same(o.projection.phi, first.projection.phi, "projection");
    same(o.projection.lambda_min, first.projection.lambda_min, "projection lambda_min");
  }
  // While another thread audits and projects another vector: the two interleave their
  // (serialized) Ipopt and CSDP calls in an order the scheduler picks. Ipopt's searches can
  // still end a last bit apart after some histories (docs/identification.md, Reproducibility),
  // and this order is not repeatable, so here to 1e-9 relative.
  std::atomic<bool> stop{false};
  std::thread other([&] {
    const Eigen::VectorXd phi1 = phi0 + 0.3 * (phi0 - truth);
    while (!stop) {
      audit_pd(*m, phi1, domain);
      project_pd(*m, phi1, domain, po);
    }
  });
  std::vector<Outcome> concurrent;
  for (int k = 0; k < 3; ++k) concurrent.push_back(solve());
  stop = true;
  other.join();
  for (const Outcome& o : concurrent) {
    same(o.audit.lambda_min, first.audit.lambda_min, "audit lambda_min, concurrent");
    same(o.projection.phi, first.projection.phi, "projection, concurrent");
  }
}

// Prints how many of the comparisons were bit-identical.
class Count : public testing::EmptyTestEventListener {
  void OnTestProgramEnd(const testing::UnitTest&) override {
    std::printf("bit-identical: %d of %d comparisons\n", identical, compared);
  }
};
const bool registered = [] {
  testing::UnitTest::GetInstance()->listeners().Append(new Count);
  return true;
}();

TEST(Determinism, CraneX7ReducedAuditAndProjection) {
  using Model = symoro::crane_x7::reduced::Model;
  const auto tc = symoro::twin::read_twin_config(SYMORO_ROBOTS_DIR "/crane_x7/twin.yaml", symoro::crane_x7::Model::nq);
  const Eigen::VectorXd truth = Model::base_from_standard(
      symoro::twin::make_truth(symoro::robot::compiled_model<symoro::crane_x7::Model>(), tc).standard);
  symoro::test::Random rng(3);
  const Eigen::VectorXd dir = rng.vector<Eigen::VectorXd>(Model::np, -1, 1).cwiseProduct(truth.cwiseAbs());
  same_bits_whatever_the_heap<Model>(truth, dir);
}

TEST(Determinism, Rx90AuditAndProjection) {
  using Model = symoro::rx90::Model;
  symoro::test::Random rng(17);
  const Eigen::VectorXd truth = Model::base_from_standard(symoro::test::random_standard_parameters<Model>(rng).s);
  const Eigen::VectorXd dir = rng.vector<Eigen::VectorXd>(Model::np, -1, 1).cwiseProduct(truth.cwiseAbs());
  same_bits_whatever_the_heap<Model>(truth, dir);
}

// Study runs as the study does them (twin logs, OLS, conditional projection in both metrics),
// again after other audits and projections: the cases where MUMPS's automatic ordering and
// automatic scaling changed the SDP vector's last bits.
TEST(Determinism, CraneX7StudyRunsAfterOtherRuns) {
  using Full = symoro::crane_x7::Model;
  using Model = symoro::crane_x7::reduced::Model;
  const std::string robot = SYMORO_ROBOTS_DIR "/crane_x7";
  const auto dir = std::filesystem::temp_directory_path() / ("symoro_determinism_" + std::to_string(::getpid()));
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      robot + "/trajectories.yaml", std::vector<symoro::JointInfo>(Model::joints.begin(), Model::joints.end()));
  symoro::test::write_twin_dataset<Full>(dir, symoro::twin::read_twin_config(robot + "/twin.yaml", Full::nq), design,
                                         {"PA01", "PA02", "PA04", "PB05", "PB07"}, 1);
  const auto pa01 = symoro::io::read_log(dir / "PA01_t1.csv");
  const auto pa02 = symoro::io::read_log(dir / "PA02_t1.csv");
  const auto pa04 = symoro::io::read_log(dir / "PA04_t1.csv");
  const auto pb05 = symoro::io::read_log(dir / "PB05_t1.csv");
  const auto pb07 = symoro::io::read_log(dir / "PB07_t1.csv");
  std::filesystem::remove_all(dir);
  const auto m = identification_model<Model>()->inertia_function();
  const AuditDomain domain = audit_domain<Model>();
  auto project = [&](const symoro::io::Log& log, double interval, bool information) {
    const auto ls = least_squares(stack_regression<Model>(symoro::preprocess::preprocess(log, interval)));
    ProjectionOptions po;
    po.shortfall_raise = 0.5;
    if (information) po.metric = information_metric(ls.information);
    const ConditionalProjection c = conditional_projection(*m, ls.phi, domain, paper_margins(), po);
    EXPECT_TRUE(c.projected && c.feasible);
    return c.phi;
  };

  const Eigen::VectorXd first = project(pa01, 0.040, false);
  for (double scale : {1.3, 0.7, 1.1, -1.0}) {
    audit_pd(*m, scale * first, domain);
    const Eigen::VectorXd again = project(pa01, 0.040, false);
    same(again, first, "after an audit of another vector");
  }
  const Eigen::VectorXd a = project(pa02, 0.010, true);
  project(pa01, 0.020, true);
  const Eigen::VectorXd b = project(pa02, 0.010, true);
  same(b, a, "after another run");
  // Where the audit kept the descent's pose after one history and Ipopt's after another.
  const Eigen::VectorXd c = project(pa04, 0.010, true), e = project(pb05, 0.010, true);
  for (const auto* other : {&pa01, &pb07}) {
    project(*other, 0.020, true);
    const Eigen::VectorXd c2 = project(pa04, 0.010, true), e2 = project(pb05, 0.010, true);
    same(c2, c, "PA04 after another run");
    same(e2, e, "PB05 after another run");
  }
}

}  // namespace
