// The identification study end to end on a small twin dataset: resumability (a rerun skips
// finished runs and gives the same result; a stale or corrupted run file is redone), the
// accepted model against an independent brute-force PD check, CLIE against the twin's truth
// (better than OLS on the parameters the data path biases), and validation RMSE against the
// twin's own floor (the truth's closed-loop simulation against the same measurement).
#include <cmath>
#include <fstream>
#include <random>

#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <symoro/crane_x7.hpp>

#include "symoro/identify/detail/closed_loop_model.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/study/validation.hpp"
#include "symoro/study/acceptance.hpp"
#include "symoro/study/study.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "twin_dataset.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"
#include "symoro/twin/truth.hpp"

namespace {

using namespace symoro;
using Full = crane_x7::Model;
using Model = crane_x7::reduced::Model;
const std::string kRobot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";
const std::vector<std::string> kIdent{"PA06", "PC09", "AP01"};
const std::vector<std::string> kValid{"V02"};

trajectory::TrajectoryDesign design() {
  return trajectory::TrajectoryDesign::read(kRobot + "/trajectories.yaml",
                                            std::vector<JointInfo>(Model::joints.begin(), Model::joints.end()));
}

// A dataset folder as dynid twin dataset writes it (logs and manifest), made once.
const std::filesystem::path& dataset() {
  static const std::filesystem::path dir = [] {
    // Per process: ctest runs test programs in parallel.
    const auto d = std::filesystem::temp_directory_path() / ("symoro_study_test_data_" + std::to_string(::getpid()));
    std::vector<std::string> names = kIdent;
    names.insert(names.end(), kValid.begin(), kValid.end());
    test::write_twin_dataset<Full>(d, twin::read_twin_config(kRobot + "/twin.yaml", Full::nq), design(), names, 5,
                                   kRobot + "/twin.yaml");
    return d;
  }();
  return dir;
}

study::StudyOptions options(const std::filesystem::path& out) {
  study::StudyOptions o;
  o.data = dataset();
  o.out = out;
  o.trajectories = kIdent;
  o.validation = kValid;
  o.intervals = {0.040, 0.080};
  o.threads = 2;
  return o;
}

identify::ClosedLoopSetup setup() {
  return identify::closed_loop_setup(twin::read_twin_config(kRobot + "/twin.yaml", Model::nq).controller);
}

struct Fixture {
  std::filesystem::path out =
      std::filesystem::temp_directory_path() / ("symoro_study_test_out_" + std::to_string(::getpid()));
  study::StudyResult first;
  int ran_first = 0;
  ~Fixture() {
    std::filesystem::remove_all(out);
    std::filesystem::remove_all(dataset());
  }
  Fixture() {
    std::filesystem::remove_all(out);
    auto o = options(out);
    o.on_run = [this](const study::RunRecord&) { ++ran_first; };
    first = study::Study(identify::identification_model<Model>(), o, design(), setup()).run();
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void runs_every_trajectory_and_interval() {
  const auto& r = fixture().first;
  ASSERT_EQ(r.runs.size(), kIdent.size() * 2);
  EXPECT_EQ(fixture().ran_first, 6);
  for (const auto& run : r.runs) {
    EXPECT_EQ(run.phi_ols.size(), Model::np) << run.id();
    EXPECT_TRUE(run.route == "O-C" || run.route == "O-S-C") << run.id();
    EXPECT_EQ(run.route == "O-C", run.ols_pd) << run.id();
    EXPECT_TRUE(run.clie_success) << run.id() << ": " << run.clie_termination;
    EXPECT_LE(run.clie_cost_final, run.clie_cost_initial) << run.id();
    // Every CLIE start is PD over the box: PD OLS, or the SDP projection of a non-PD one.
    EXPECT_TRUE(run.sdp_feasible) << run.id();
  }
  ASSERT_GE(r.selection.run, 0);
}

// A rerun finds every run finished: nothing is recomputed and the result is the same.
void rerun_skips_finished_runs_and_redoes_stale_ones() {
  auto& f = fixture();
  int ran = 0, skipped = -1;
  auto o = options(f.out);
  o.on_run = [&](const study::RunRecord&) { ++ran; };
  o.on_start = [&](int, int s) { skipped = s; };
  const auto again = study::Study(identify::identification_model<Model>(), o, design(), setup()).run();
  EXPECT_EQ(ran, 0);
  EXPECT_EQ(skipped, 6);
  ASSERT_EQ(again.runs.size(), f.first.runs.size());
  for (size_t i = 0; i < again.runs.size(); ++i) EXPECT_EQ(again.runs[i].phi_clie, f.first.runs[i].phi_clie);
  EXPECT_EQ(again.selection.run, f.first.selection.run);

  // A truncated run file (a crash while something else wrote it) and one from other options
  // are both redone; their trajectory's other runs are kept.
  const auto runs = f.out / "runs";
  { std::ofstream(runs / "PA06@40ms.yaml") << "format: symoro-identification-run 1\nfingerprint: "; }
  YAML::Node n = YAML::LoadFile((runs / "PC09@80ms.yaml").string());
  n["fingerprint"] = "0000000000000000";
  { std::ofstream(runs / "PC09@80ms.yaml") << n; }
  ran = 0;
  std::vector<std::string> redone;
  o.on_run = [&](const study::RunRecord& r) { redone.push_back(r.id()); };
  const auto third = study::Study(identify::identification_model<Model>(), o, design(), setup()).run();
  std::sort(redone.begin(), redone.end());
  EXPECT_EQ(redone, (std::vector<std::string>{"PA06@40ms", "PC09@80ms"}));
  for (size_t i = 0; i < third.runs.size(); ++i)
    EXPECT_LT((third.runs[i].phi_ols - f.first.runs[i].phi_ols).norm(), 1e-12) << third.runs[i].id();
}

// The accepted model is PD everywhere: an independent check by dense random sampling.
void accepted_model_is_positive_definite_by_brute_force() {
  const auto& r = fixture().first;
  ASSERT_TRUE(r.accepted);
  ASSERT_EQ(r.phi_rescue.size(), Model::np);
  const auto dom = identify::audit_domain<Model>();
  std::mt19937_64 rng(99);
  double worst = 1e9;
  for (int k = 0; k < 100000; ++k) {
    Eigen::Matrix<double, Model::nq, 1> q;
    for (int j = 0; j < Model::nq; ++j) q(j) = std::uniform_real_distribution<double>(dom.lower(j), dom.upper(j))(rng);
    Eigen::Matrix<double, Model::nq, Model::nq> M;
    Model::inertia(q, r.phi_rescue, M);
    worst = std::min(worst, Eigen::SelfAdjointEigenSolver<decltype(M)>(M, Eigen::EigenvaluesOnly).eigenvalues()(0));
  }
  EXPECT_GT(worst, 0);
  EXPECT_LE(r.final_lambda_min, worst + 1e-12);  // the audit finds at least as bad a pose
}

// Validation: the accepted model's closed-loop torque error on held-out V02 against the floor
// the twin itself sets (its truth simulated the same way: quantization, noise, the products of
// inertia the reduced model lacks).
void validation_is_near_the_twins_floor() {
  const auto& r = fixture().first;
  ASSERT_EQ(r.validation.size(), 1u);
  const auto& v = r.validation.front();
  const auto tc = twin::read_twin_config(kRobot + "/twin.yaml", Full::nq);
  const Eigen::VectorXd truth =
      Model::base_from_standard(twin::make_truth(symoro::robot::compiled_model<Full>(), tc).standard);
  const identify::ClosedLoopSimulator<Model> sim(setup(), design().build("V02"));
  const auto log = io::read_log(dataset() / "V02_t1.csv");
  const auto s = preprocess::preprocess(log, v.interval);
  const auto floor = study::validate_trajectory<Model>(&sim, s, truth, truth, identify::ClieOptions{});
  std::printf("V02 at %.0f ms: RMSE accepted %.4f, CLIE %.4f, truth floor %.4f N m; MNE %.4f / floor %.4f\n",
              v.interval * 1e3, v.rmse_rescue, v.rmse_clie, floor.rmse_clie, v.mne_rescue, floor.mne_clie);
  EXPECT_LT(v.rmse_rescue, 1.5 * floor.rmse_clie);
  EXPECT_LT(v.mne_rescue, 1.5 * floor.mne_clie);
  // And the metrics are what they say: recomputed from the stored series.
  const study::TorqueError e = study::torque_error(v.tau_measured, v.tau_rescue);
  EXPECT_NEAR(e.rmse, v.rmse_rescue, 1e-12);
}

// One test: the study runs once per process (it is the expensive part), the checks follow.
TEST(Study, EndToEndOnTwinData) {
  {
    SCOPED_TRACE("runs every trajectory and interval");
    runs_every_trajectory_and_interval();
  }
  {
    SCOPED_TRACE("accepted model is PD by brute force");
    accepted_model_is_positive_definite_by_brute_force();
  }
  {
    SCOPED_TRACE("validation near the twin's floor");
    validation_is_near_the_twins_floor();
  }
  {
    SCOPED_TRACE("rerun skips finished runs, redoes stale ones");
    rerun_skips_finished_runs_and_redoes_stale_ones();
  }
}

// The acceptance rule's steps on their own (acceptance.hpp).
TEST(Acceptance, FinalAuditIsDenserAndOnOtherPoses) {
  identify::AuditOptions pipeline;
  pipeline.samples = 1000;
  pipeline.starts = 5;
  pipeline.seed = 3;
  const identify::AuditOptions a = study::final_audit_options(pipeline, study::FinalAuditOptions{});
  EXPECT_EQ(a.samples, 4000);
  EXPECT_EQ(a.starts, 10);
  EXPECT_EQ(a.seed, 3u + 7919u);
  EXPECT_EQ(study::describe(a), "4000 quasi-random poses, 10 local minimizations, seed 7922");
  study::FinalAuditOptions same;
  same.sample_factor = 1, same.start_factor = 1, same.seed_offset = 0;
  EXPECT_EQ(study::final_audit_options(pipeline, same).samples, 1000);
}

TEST(Acceptance, PriorWeightBySmallestHeldOutErrorSmallerOnATie) {
  // Each weight's "rescue" is a vector holding the weight; held-out errors by hand: 1e-4 is
  // 0.05 % worse than 1e-2 (a tie: the smaller weight stays), 1 is best but infeasible.
  const auto rescue = [](double w) {
    identify::PhysicalProjection p;
    p.phi = Eigen::VectorXd::Constant(1, w);
    p.feasible = w < 0.5;
    return p;
  };
  const auto rmse = [](const Eigen::VectorXd& phi) {
    const double w = phi(0);
    return w == 1e-6 ? 2.0 : w == 1e-4 ? 1.0005 : w == 1e-2 ? 1.0 : 0.5;
  };
  const study::PriorWeightChoice c = study::choose_prior_weight({1e-6, 1e-4, 1e-2, 1.0}, 1e-6, rescue, rmse);
  EXPECT_EQ(c.weight, 1e-4);
  EXPECT_EQ(c.projection.phi(0), 1e-4);
  ASSERT_EQ(c.scores.size(), 4u);
  EXPECT_EQ(c.scores[3].second, 0.5);
  // None feasible: the default weight's rescue.
  const auto never = [](double w) {
    identify::PhysicalProjection p;
    p.phi = Eigen::VectorXd::Constant(1, w);
    return p;
  };
  const study::PriorWeightChoice d = study::choose_prior_weight({1e-4, 1e-2}, 1e-6, never, rmse);
  EXPECT_EQ(d.weight, 1e-6);
  EXPECT_EQ(d.projection.phi(0), 1e-6);
}

TEST(Acceptance, TheVerdictSaysWhyNot) {
  study::StudyResult r;
  EXPECT_FALSE(study::acceptance_verdict(r).accepted);
  EXPECT_EQ(study::acceptance_verdict(r).reasons.front(), "no representative run: no run produced a final vector");
  r.selection.run = 0;
  r.final_lambda_min = 1e-3;
  r.consistency = "pd";
  EXPECT_TRUE(study::acceptance_verdict(r).accepted);
  EXPECT_TRUE(study::acceptance_verdict(r).reasons.empty());
  // The PD path does not ask for a consistent set; the physical path does.
  r.consistency = "physical";
  r.final_consistent = false;
  r.final_consistency_note = "link 3's pseudo-inertia is not positive definite";
  study::Verdict v = study::acceptance_verdict(r);
  EXPECT_FALSE(v.accepted);
  ASSERT_EQ(v.reasons.size(), 1u);
  EXPECT_EQ(v.reasons[0],
            "no physically consistent set maps onto it (link 3's pseudo-inertia is not positive definite)");
  // A failed audit after a failed rescue: both said, the audit first.
  r.final_consistent = true;
  r.final_lambda_min = -2e-4;
  r.rescued = true;
  r.rescue_feasible = false;
  r.rescue_status = "the SDP solver stopped";
  v = study::acceptance_verdict(r);
  EXPECT_FALSE(v.accepted);
  ASSERT_EQ(v.reasons.size(), 2u);
  EXPECT_EQ(v.reasons[0], "the final audit found M(q) not positive definite (lambda_min -0.0002)");
  EXPECT_EQ(v.reasons[1], "the rescue's projection failed (the SDP solver stopped)");
}

TEST(Acceptance, RepresentativeOfNoRunOneRunAndACloud) {
  std::vector<study::RunRecord> runs(1);
  runs[0].failed = true;
  EXPECT_FALSE(study::select_representative(runs, 3, 0.9).has_value());
  runs[0].failed = false;
  runs[0].phi_clie = Eigen::VectorXd::Ones(4);
  const auto one = study::select_representative(runs, 3, 0.9);
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->selection.run, 0);
  EXPECT_EQ(one->selection.rule, "the only run (no PCA cloud)");
}

}  // namespace
