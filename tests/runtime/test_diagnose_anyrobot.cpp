// The model-gap workflow on robots without a digital twin (the RX-90 and the Stanford RRP arm,
// whose third joint is prismatic),
// from logs synthesized here with their generated models (synthetic_log.hpp: multi-sine
// excitation, jittered stamps, stale rows, noise), never from the project's twin:
//   - a constant torque offset on any one joint, which the model has no term for, is named on
//     that joint with its size (the offset's own residual once capped its F below the level);
//   - a controller's CSV export (degrees, milliseconds, its own column names) goes through
//     import (split 70 / 30 by time), identification without a controller description,
//     diagnosis of the model without Coulomb friction (`rigid`, while the data have it, and an
//     offset on the last joint), and the comparison of its study against the full model's.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>

#include "symoro/diagnose/diagnosis.hpp"
#include "symoro/diagnose/gap_report.hpp"
#include "symoro/diagnose/stack_builder.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/study/study.hpp"
#include "symoro/study/validation_io.hpp"
#include "symoro/io/import.hpp"
#include "../removed_at_exit.hpp"
#include "symoro/diagnose/dataset_diagnosis.hpp"
#include "symoro/io/text_file.hpp"
#include "synthetic_log.hpp"
#include "test_support.hpp"

namespace {

using namespace symoro;

// The robot's full model (the data's truth), the model diagnosed and compared before, and the
// model compared after.
template <class F, class B, class A>
struct Models {
  using Full = F;
  using Before = B;
  using After = A;
};

template <class P>
class AnyRobotGap : public ::testing::Test {
 protected:
  using Full = typename P::Full;
  using Phi = Eigen::Matrix<double, Full::np, 1>;

  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("symoro_anyrobot_gap_") + Full::robot_name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    test::Random rng(23);
    truth_ = Full::base_from_standard(test::random_standard_parameters<Full>(rng).s);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Fitting and held-out stacks of the diagnosis (identified model `Model`), from logs.
  template <class Model>
  static diagnose::DesignStack stack(const std::vector<io::Log>& logs) {
    std::vector<diagnose::NamedSamples> runs;
    for (const auto& log : logs)
      runs.push_back(
          {log.meta.trajectory, preprocess::preprocess(log, log.meta.sample_time, diagnose::light_preprocessing())});
    return diagnose::stack_design<Full, Model>(runs, diagnose::StackOptions{});
  }

  static const diagnose::SelectedEffect* find(const diagnose::Selection& s, diagnose::EffectKind kind, int joint) {
    for (const auto& e : s.effects)
      if (e.candidate.kind == kind && e.candidate.joint == joint) return &e;
    return nullptr;
  }

  std::filesystem::path dir_;
  Phi truth_;
};

using Robots = ::testing::Types<Models<rx90::Model, rx90::rigid::Model, rx90::Model>,
                                Models<stanford_rrp::Model, stanford_rrp::rigid::Model, stanford_rrp::Model>>;
TYPED_TEST_SUITE(AnyRobotGap, Robots);

TYPED_TEST(AnyRobotGap, AnOffsetOnAnyJointIsNamed) {
  using Full = typename TestFixture::Full;
  for (int j = 1; j <= Full::nq; ++j) {
    // 0.05 N m on a revolute joint; a prismatic joint's is a force, 0.2 N (its gravity column,
    // m g cos q2 on the Stanford arm's boom, absorbs more of a constant).
    const double size = Full::joints[j - 1].type == JointType::Prismatic ? 0.2 : 0.05;
    const double offset = size * (j % 2 ? 1 : -1);
    const auto train =
        test::synthesize<Full>("R1", this->truth_, 30.0, 10 * j + 1, 0.05, test::offset_on<Full>(j, offset));
    const auto held =
        test::synthesize<Full>("H1", this->truth_, 20.0, 10 * j + 2, 0.05, test::offset_on<Full>(j, offset));
    const diagnose::Diagnosis d =
        diagnose::diagnose(TestFixture::template stack<Full>({train}), TestFixture::template stack<Full>({held}));
    const auto* e = TestFixture::find(d.selection, diagnose::EffectKind::Offset, j);
    if (!e && !d.selection.steps.empty())
      for (const auto& t : d.selection.steps[0].tests)
        if (t.key.find("offset") != std::string::npos || t.f > 5)
          std::cout << fmt::format(
              "  {:28s} F {:8.1f} p {:.1e} level {:.1e} gain {:.4f} all {:.4f} phys {} matters {} rms {:.4f} df2 "
              "{:.0f} {}\n",
              t.key, t.f, t.p_value, d.selection.steps[0].level, t.heldout_gain, t.heldout_reduction, t.physical,
              t.matters, t.effect_rms, t.df2, t.absorbed ? "absorbed" : "");
    ASSERT_NE(e, nullptr) << "offset on joint " << j << " not named (" << d.selection.stop_reason << ")";
    // Added to the measured torque: the diagnosis finds it as it is (a twin offset is external).
    EXPECT_NEAR(e->magnitude.values[0], offset, 0.2 * std::abs(offset)) << "joint " << j << ": " << e->magnitude.text;
    for (const auto& other : d.selection.effects)
      EXPECT_TRUE(&other == e) << "joint " << j << ": spurious " << other.candidate.label() << " "
                               << other.magnitude.text;
    EXPECT_LT(d.selection.after.heldout_total, d.selection.before.heldout_total) << "joint " << j;
  }
}

TYPED_TEST(AnyRobotGap, AControllersCsvThroughImportIdentifyDiagnoseAndCompare) {
  using Full = typename TestFixture::Full;
  using Before = typename TypeParam::Before;
  using After = typename TypeParam::After;
  constexpr int n = Full::nq;
  const int offset_joint = n;  // the last joint, -0.06 N m
  const io::Log log =
      test::synthesize<Full>("arm", this->truth_, 60.0, 5, 0.05, test::offset_on<Full>(offset_joint, -0.06));

  // The controller's export: milliseconds, degrees (m for a prismatic joint), its own column
  // names, a text column.
  const auto csv = this->dir_ / "export.csv";
  test::write_export_csv<Full>(log, csv);
  io::DatasetImport im;
  im.target.robot = Full::robot_name;
  for (const auto& J : Full::joints) {
    im.target.joints.emplace_back(J.name);
    im.target.prismatic.push_back(J.type == JointType::Prismatic);
  }
  im.mapping.time = "stamp_ms";
  im.mapping.q = "{name}_pos";
  im.mapping.qd = "{name}_vel";
  im.mapping.tau = "{name}_eff";
  im.mapping.time_unit = io::TimeUnit::ms;
  im.mapping.angle_unit = io::AngleUnit::deg;
  im.inputs.push_back({csv, "arm", false});
  im.split = 0.7;
  const io::DatasetImportResult imported = io::import_dataset(this->dir_ / "data", im);
  ASSERT_EQ(imported.runs.size(), 2u);
  int stale = 0;
  for (int i = 1; i < log.samples(); ++i)
    stale += log.q.row(i) == log.q.row(i - 1) && log.tau.row(i) == log.tau.row(i - 1);
  EXPECT_EQ(static_cast<int>(imported.logs[0].stale_lines.size()), stale);
  EXPECT_GT(stale, log.samples() / 40);

  // Identification of both models, no controller description: open loop on arm_heldout.
  auto study = [&](auto model, const std::string& name) {
    using Model = decltype(model);
    study::StudyOptions o;
    o.data = this->dir_ / "data";
    o.out = this->dir_ / name;
    o.intervals = {0.010};
    study::Study s(identify::identification_model<Model>(), o, study::ClosedLoopSource{});
    const study::StudyResult r = s.run();
    study::write_validation(r, o.out);
    return r;
  };
  const study::StudyResult before_study = study(Before{}, "study-before"), after_study = study(After{}, "study-after");
  for (const auto* r : {&before_study, &after_study}) {
    ASSERT_EQ(r->runs.size(), 1u);
    EXPECT_EQ(r->runs[0].trajectory, "arm");
    std::string stages = r->selection.rule;
    for (const auto& line : r->stages) stages += "\n" + line;
    ASSERT_EQ(r->validation.size(), 1u) << stages;
    EXPECT_EQ(r->validation[0].trajectory, "arm_heldout");
    EXPECT_EQ(r->validation[0].kind, "open-loop");
  }
  // The held-out part is the last 30 % of the log, by time.
  const io::Dataset data = io::read_dataset(this->dir_ / "data");
  const io::Log held = io::read_run_log(data.find("arm_heldout", 1), Full::robot_name, n);
  EXPECT_NEAR(held.time(0) - log.time(0), 0.7 * (log.time(log.samples() - 1) - log.time(0)), 0.002);

  // Diagnosis of the model before on the dataset's split: Coulomb friction on every joint where
  // that model lacks it (and nowhere else), and the offset on its joint. The import converted
  // exactly (the prismatic joint left in m): the held-out part's q is the synthesized one.
  // (Stamps went through milliseconds in text: equal to the synthesized ones to rounding.)
  for (int i = 0; i < held.samples(); i += 997) {
    Eigen::Index k = 0;
    (log.time.array() - held.time(i)).abs().minCoeff(&k);
    ASSERT_NEAR(log.time(k), held.time(i), 1e-12);
    for (int j = 0; j < n; ++j) EXPECT_NEAR(held.q(i, j), log.q(k, j), 1e-12 * (1 + std::abs(log.q(k, j))));
  }
  const diagnose::Diagnosis d = diagnose::diagnose(
      TestFixture::template stack<Before>({io::read_run_log(data.find("arm", 1), Full::robot_name, n)}),
      TestFixture::template stack<Before>({held}));
  auto has = [](auto model, const std::string& name) {
    for (const auto& p : decltype(model)::parameters)
      if (name == p.name) return true;
    return false;
  };
  for (int j = 1; j <= n; ++j) {
    double fs = 0;  // the truth's Coulomb friction on joint j
    for (int i = 0; i < Full::np; ++i)
      if (std::string(Full::parameters[i].name) == "FS" + std::to_string(j)) fs = this->truth_(i);
    const auto* c = TestFixture::find(d.selection, diagnose::EffectKind::Coulomb, j);
    if (has(Before{}, "FS" + std::to_string(j))) {
      EXPECT_EQ(c, nullptr) << "Coulomb friction named on joint " << j << ", which the model has";
      continue;
    }
    ASSERT_NE(c, nullptr) << "Coulomb friction " << fs << " N m on joint " << j << " not named";
    EXPECT_EQ(c->candidate.parameters.at(0), "FC" + std::to_string(j));  // as the variant compiles it
    EXPECT_NEAR(c->magnitude.values[0], fs, 0.25 * fs) << "joint " << j << ": " << c->magnitude.text;
  }
  const auto* off = TestFixture::find(d.selection, diagnose::EffectKind::Offset, offset_joint);
  ASSERT_NE(off, nullptr) << "the offset on joint " << offset_joint << " was not named";
  EXPECT_NEAR(off->magnitude.values[0], -0.06, 0.2 * 0.06) << off->magnitude.text;
  for (const auto& e : d.selection.effects)
    EXPECT_TRUE(e.candidate.kind == diagnose::EffectKind::Coulomb || e.candidate.kind == diagnose::EffectKind::Offset)
        << "spurious " << e.candidate.label() << " " << e.magnitude.text;
  EXPECT_LT(d.selection.after.heldout_total, 0.9 * d.selection.before.heldout_total);

  // The comparison: the model with what the data have validates better on the held-out part.
  const auto before = study::read_validation(this->dir_ / "study-before");
  const auto after = study::read_validation(this->dir_ / "study-after");
  const diagnose::GapComparison c = diagnose::compare_studies(before, after);
  ASSERT_EQ(c.trajectories.size(), 1u);
  EXPECT_EQ(c.trajectories[0].kind, "open-loop");
  EXPECT_LT(c.rmse_after, 0.9 * c.rmse_before) << c.rmse_before << " -> " << c.rmse_after;
  std::size_t added = 0;
  for (const auto& p : After::parameters) added += !has(Before{}, p.name);
  EXPECT_EQ(c.added.size(), added);
  EXPECT_NO_THROW(diagnose::write_gap_report(before, after, c, this->dir_ / "gap", {}));
  EXPECT_TRUE(std::filesystem::exists(this->dir_ / "gap" / "gap.md"));
}

}  // namespace

namespace {

// --apply keeps every selected effect: Coulomb friction selected with different velocity
// spreads on two joints becomes one smooth_coulomb entry with a width per joint (a variant holds
// one entry per effect; the second width used to become a comment, and the applied model lost
// it). The width is the tanh's of the spread's erf slope at rest: spread sqrt(pi / 2).
TEST(DiagnoseVariant, EverySelectedWidthIsKept) {
  using symoro::diagnose::EffectKind;
  symoro::diagnose::Diagnosis d;
  for (const auto& [kind, joint, width] :
       {std::tuple{EffectKind::Coulomb, 4, 0.01}, std::tuple{EffectKind::Offset, 5, 0.0},
        std::tuple{EffectKind::Coulomb, 2, 0.03}}) {
    symoro::diagnose::SelectedEffect e;
    e.candidate.kind = kind;
    e.candidate.joint = joint;
    e.candidate.coulomb_velocity = width;
    d.selection.effects.push_back(e);
  }
  const std::string y = symoro::diagnose::variant_yaml(d, "reduced_diagnosed", "reduced");
  EXPECT_NE(y.find("      smooth_coulomb: {joints: [2, 4], velocity: [0.0375994, 0.0125331]}\n"), std::string::npos)
      << y;
  EXPECT_NE(y.find("      offset: [5]\n"), std::string::npos) << y;
  EXPECT_EQ(y.find("# also"), std::string::npos) << y;
  EXPECT_NE(y.find("    base: reduced\n"), std::string::npos) << y;
  // A diagnosis of the full model: robot.yaml knows no variant "full" (symoroc refused "base: full"
  // after dynid diagnose --apply), the full model is where every variant starts.
  const std::string of_full = symoro::diagnose::variant_yaml(d, "diagnosed", "full");
  EXPECT_EQ(of_full.find("base:"), std::string::npos) << of_full;
  EXPECT_NE(of_full.find("    effects:\n"), std::string::npos) << of_full;
}

// --apply on a robot.yaml without a `variants:` section (what symoroc model writes for a URDF)
// adds the section; on one whose last section is `variants:` it appends to it.
TEST(DiagnoseVariant, ApplyAddsTheVariantsSectionARobotYamlLacks) {
  namespace fs = std::filesystem;
  const fs::path dir = symoro::test::removed_at_exit(fmt::format("symoro_apply_{}", ::getpid()));
  fs::create_directories(dir);
  const fs::path yaml = dir / "robot.yaml";
  std::string original = symoro::io::read_text_file(std::string(SYMORO_ROBOTS_DIR) + "/stanford_rrp/robot.yaml");
  original = original.substr(0, original.find("\nvariants:") + 1);  // the robot without its variants
  { std::ofstream(yaml) << original; }
  symoro::diagnose::Diagnosis d;
  symoro::diagnose::SelectedEffect e;
  e.candidate.kind = symoro::diagnose::EffectKind::Offset;
  e.candidate.joint = 2;
  d.selection.effects.push_back(e);
  symoro::diagnose::add_variant_to_robot_yaml(yaml, "diagnosed",
                                              symoro::diagnose::variant_yaml(d, "diagnosed", "full"));
  const std::string once = symoro::io::read_text_file(yaml);
  EXPECT_EQ(once.substr(0, original.size()), original);
  EXPECT_EQ(once.substr(original.size()), "variants:\n" + symoro::diagnose::variant_yaml(d, "diagnosed", "full"));
  symoro::diagnose::add_variant_to_robot_yaml(yaml, "again", symoro::diagnose::variant_yaml(d, "again", "full"));
  const std::string twice = symoro::io::read_text_file(yaml);
  EXPECT_EQ(twice.find("\nvariants:"), twice.rfind("\nvariants:")) << "one section: " << twice;
  EXPECT_EQ(twice.substr(once.size()), symoro::diagnose::variant_yaml(d, "again", "full"));
  EXPECT_THROW(
      symoro::diagnose::add_variant_to_robot_yaml(yaml, "again", symoro::diagnose::variant_yaml(d, "again", "full")),
      symoro::diagnose::DiagnosisRequestError);
}

}  // namespace
