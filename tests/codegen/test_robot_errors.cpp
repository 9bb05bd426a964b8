// Bad robot folders get errors that name the file, the line and the problem; good ones load.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <utility>
#include <vector>

#include "symoro/codegen/generator.hpp"
#include "symoro/codegen/robot_model.hpp"
#include "symoro/grammar/parser.hpp"

namespace fs = std::filesystem;
using namespace symoro::codegen;

namespace {

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A scratch copy of robots/planar2r in which one file is edited.
class BrokenRobot : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("symoro_broken_" + std::to_string(::getpid())) / "arm";
    fs::remove_all(dir_.parent_path());
    fs::create_directories(dir_.parent_path());
    fs::copy(fs::path(SYMORO_ROBOTS_DIR) / "planar2r", dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }

  // Starts from another folder of robots/ instead.
  void start_from(const std::string& robot) {
    fs::remove_all(dir_);
    fs::copy(fs::path(SYMORO_ROBOTS_DIR) / robot, dir_);
  }

  void replace(const std::string& file, const std::string& from, const std::string& to) {
    std::string text = read(dir_ / file);
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(dir_ / file) << text;
  }

  // Adds variants (YAML lines indented by two spaces) to robot.yaml's `variants:` map, which
  // ends the file: its first line is line kFirstAddedLine.
  void add_variants(const std::string& yaml) { std::ofstream(dir_ / "robot.yaml", std::ios::app) << yaml; }
  static constexpr int kFirstAddedLine = 29;

  // Loading and generating must fail with a message matching `pattern`.
  void expect_error(const std::string& pattern) {
    try {
      RobotModel r = load_robot(dir_.string());
      generate_robot(r);
      FAIL() << "no error; expected " << pattern;
    } catch (const std::exception& e) {
      EXPECT_TRUE(std::regex_search(e.what(), std::regex(pattern))) << e.what();
    }
  }

  fs::path dir_;
};

}  // namespace

TEST_F(BrokenRobot, LoadsWhenUntouched) {
  RobotModel r = load_robot(dir_.string());
  EXPECT_EQ(r.name, "arm");
  EXPECT_EQ(r.n, 2);
  EXPECT_EQ(r.base.size(), 11u);
  EXPECT_EQ(r.base.front().name, "ZZR1");
  EXPECT_EQ(r.standard.size(), 26u);
}

TEST_F(BrokenRobot, UnknownSymbolInAnEquation) {
  replace("dim.txt", "VP11 = G3*S1;", "VP11 = G4*S1;");
  expect_error(R"(dim\.txt:30:8: error: unknown symbol 'G4')");
}

TEST_F(BrokenRobot, SyntaxErrorNamesLineAndColumn) {
  replace("idm.txt", "W32 = QP1 + QP2;", "W32 = QP1 + * QP2;");
  expect_error(R"(idm\.txt:34:\d+: error: )");
}

TEST_F(BrokenRobot, MissingConstantIsReportedInTheParFile) {
  replace("robot.yaml", "  L1: 0.5         # m, first link length\n", "");
  expect_error(R"(planar2r\.par:13:\d+: error: unknown symbol 'L1')");
}

TEST_F(BrokenRobot, JointCountMismatch) {
  replace("robot.yaml", "  - {name: elbow,    lower: -150 deg, upper: 150 deg, velocity: 3.0, effort: 20.0}\n", "");
  expect_error(R"(robot\.yaml:0:0: error: robot\.yaml lists 1 joints but .*NJ = 2)");
}

TEST_F(BrokenRobot, BadJointLimitsPointAtTheYamlLine) {
  replace("robot.yaml", "lower: -150 deg, upper: 150 deg", "lower: 150 deg, upper: -150 deg");
  expect_error(R"(robot\.yaml:10:\d+: error: joint elbow: upper must exceed lower)");
}

// A misspelt key is refused at its line with the key it resembles, not ignored, on two robots.
TEST_F(BrokenRobot, MisspeltKeyNamesItsLineAndTheNearestKey) {
  replace("robot.yaml", "{name: elbow,    lower: -150 deg", "{name: elbow,    lowr: -150 deg");
  expect_error(
      R"(robot\.yaml:10:\d+: error: unknown key 'lowr' in a joint; did you mean 'lower'\? \(known keys: name, lower, )");
  start_from("rx90");
  replace("robot.yaml", "parameter_units:", "parameter_unts:");
  expect_error(
      R"(robot\.yaml:17:1: error: unknown key 'parameter_unts' in robot\.yaml; did you mean 'parameter_units'\?)");
  start_from("rx90");
  replace("robot.yaml", "    fixed: {\"FS*\": 0}", "    fixde: {\"FS*\": 0}");
  expect_error(R"(robot\.yaml:26:5: error: unknown key 'fixde' in variant rigid; did you mean 'fixed'\?)");
  start_from("rx90");
  replace("robot.yaml", "MX: kg*m, MY", "MX: kg*m, YM");
  expect_error(R"(robot\.yaml:19:24: error: unknown parameter family 'YM'; did you mean 'MY'\?)");
  start_from("planar2r");
  replace("robot.yaml", "      stribeck:", "      stribek:");
  expect_error(
      R"(robot\.yaml:\d+:7: error: variant effects: unknown effect 'stribek'; did you mean 'stribeck'\? \(known effects: )");
}

// yaml-cpp reads a quoted value without its closing quote as text to the end of the file (here
// every key after the description): a syntax error at the opening quote instead. (A later quote
// in the file would close it: the variant's "FS*" is written without quotes here.)
TEST_F(BrokenRobot, UnclosedQuoteIsASyntaxError) {
  start_from("stanford_rrp");
  replace("robot.yaml", "fixed: {\"FS*\": 0}", "fixed: {FS*: 0}");
  replace("robot.yaml", "description: ", "description: \"");
  expect_error(R"(robot\.yaml:2:14: error: YAML syntax error: the quoted value opened here by " has no closing quote)");
  start_from("rx90");
  replace("robot.yaml", "  D3: 0.45 ", "  D3: [0.45 ");
  expect_error(R"(robot\.yaml:\d+:\d+: error: YAML syntax error: )");
}

// A self-merging alias crashed symoroc generate (a stack overflow); a second document was
// ignored. Both are refused at their line.
TEST_F(BrokenRobot, ACycleOfAliasesOrASecondDocumentIsRefusedAtItsLine) {
  add_variants("  loop: &s {<<: *s}\n");
  expect_error(R"(robot\.yaml:\d+:\d+: error: a YAML alias inside the node its anchor names: a cycle)");
  start_from("stanford_rrp");
  std::ofstream(dir_ / "robot.yaml", std::ios::app) << "---\nname: other\n";
  expect_error(R"(robot\.yaml:\d+:\d+: error: a second YAML document)");
}

// A map given where robot.yaml wants a map is an error at its line, not a yaml-cpp exception
// (fuzz_yaml found the variant case).
TEST_F(BrokenRobot, AScalarWhereAMapBelongsIsRefusedAtItsLine) {
  add_variants("  light: frictionless\n");
  expect_error("robot\\.yaml:" + std::to_string(kFirstAddedLine) +
               R"(:10: error: variant light must be a mapping \(description, base, fixed, effects\))");
  start_from("rx90");
  replace("robot.yaml", "parameter_units:\n  revolute:", "parameter_units: SI\nnominal:\n  revolute:");
  expect_error(R"(robot\.yaml:17:18: error: parameter_units must be a mapping \(revolute, prismatic\))");
}

TEST_F(BrokenRobot, VariantPatternThatMatchesNothing) {
  add_variants("  light:\n    fixed: {\"XY*\": 0}\n");
  expect_error(R"(robot\.yaml:\d+:1: error: variant light: 'XY\*' matches no base parameter)");
}

TEST_F(BrokenRobot, UnknownRegressorEntry) {
  replace("dim.txt", "DG2FV2 = QP2;", "DG2FV2 = QP2;\nDG2FV9 = QP2;");
  expect_error(R"(dim\.txt:\d+:1: error: 'DG2FV9' names no joint and base parameter)");
}

TEST_F(BrokenRobot, CcgMustNotUseAccelerations) {
  replace("ccg.txt", "GAM2 = FS2*sign(QP2) + FV2*QP2 + N32;", "GAM2 = FS2*sign(QP2) + FV2*QP2 + N32 + QDP2;");
  expect_error(R"(ccg\.txt:\d+:\d+: error: unknown symbol 'QDP2'.*Coriolis and gravity model)");
}

TEST_F(BrokenRobot, MissingFile) {
  fs::remove(dir_ / "jac.txt");
  expect_error(R"(jac\.txt.*cannot open)");
}

TEST_F(BrokenRobot, VariantFixesParametersAndKeepsTheRest) {
  add_variants("  frictionless:\n    fixed: {\"FS*\": 0, \"FV*\": 0}\n");
  RobotModel r = load_robot(dir_.string());
  const Generation gen = generate_robot(r);
  ASSERT_EQ(gen.models.size(), 3u);  // the full model, planar2r's `effects`, this one
  EXPECT_EQ(gen.models[2].name, "arm::frictionless");
  EXPECT_EQ(gen.models[2].identified.size(), 7u);
  EXPECT_EQ(gen.models[2].fixed.size(), 4u);
}

// ---- variants with `base:` and `effects:` (planar2r's robot.yaml has the variant `effects`,
// lines 19-27: fixed {"FS*": 0}; coulomb [1]; offset [1, 2]; stribeck joint 2 at 0.05;
// viscous_asymmetry [2]; position_harmonics joint 1, orders 1 and 2).

std::vector<std::string> names_of(const std::vector<ParameterRef>& ps) {
  std::vector<std::string> out;
  for (const auto& p : ps) out.push_back(p.name);
  return out;
}

TEST_F(BrokenRobot, EffectsUnfixAndAppendParametersInCanonicalOrder) {
  RobotModel r = load_robot(dir_.string());
  const Generation gen = generate_robot(r);
  ASSERT_EQ(gen.models.size(), 2u);
  const ModelSummary& m = gen.models[1];
  EXPECT_EQ(m.name, "arm::effects");
  EXPECT_EQ(
      names_of(m.identified),
      (std::vector<std::string>{"ZZR1", "MXR1", "MY1",  "ZZ2",  "MX2",   "MY2",   "IA2",   "FV1",   "FV2", "FS1",
                                "OFF1", "OFF2", "FST2", "FVA2", "HS1_1", "HC1_1", "HS1_2", "HC1_2", "FC2", "FSE2"}));
  ASSERT_EQ(m.fixed.size(), 1u);  // "FS*" matches FS1 and FS2; coulomb [1] un-fixes FS1
  EXPECT_EQ(m.fixed[0].first, "FS2");
  EXPECT_EQ(m.identified[13].unit, "N*m*s/rad");
  ASSERT_EQ(m.effects.size(), 10u);
  EXPECT_EQ(m.effects[2], (std::pair<std::string, std::string>{"FST2", "sign(QP2)*exp(-(QP2/0.05)^2)"}));
  EXPECT_EQ(m.effects[6], (std::pair<std::string, std::string>{"HS1_2", "sin(2*th1)"}));
  EXPECT_EQ(m.effects[8], (std::pair<std::string, std::string>{"FC2", "tanh(QP2/0.04)"}));
  EXPECT_EQ(m.effects[9], (std::pair<std::string, std::string>{"FSE2", "sign(QP2)*exp(-(|QP2|/0.08))"}));
}

TEST_F(BrokenRobot, BaseVariantChainsFixedPatternsAndEffects) {
  add_variants(
      "  more:\n"
      "    base: effects\n"
      "    fixed: {\"FV2\": 0}\n"
      "    effects:\n"
      "      position_harmonics: {joints: [2], orders: [3]}\n"
      "      stribeck: {joints: [1]}\n"
      "  most:\n"
      "    base: more\n");
  RobotModel r = load_robot(dir_.string());
  const Generation gen = generate_robot(r);
  ASSERT_EQ(gen.models.size(), 4u);
  for (std::size_t k : {2u, 3u}) {
    const ModelSummary& m = gen.models[k];
    SCOPED_TRACE(m.name);
    EXPECT_EQ(names_of(m.identified),
              (std::vector<std::string>{"ZZR1",  "MXR1",  "MY1",   "ZZ2",   "MX2",  "MY2",  "IA2",   "FV1",
                                        "FS1",   "OFF1",  "OFF2",  "FST1",  "FST2", "FVA2", "HS1_1", "HC1_1",
                                        "HS1_2", "HC1_2", "HS2_3", "HC2_3", "FC2",  "FSE2"}));
    EXPECT_EQ(m.fixed, (std::vector<std::pair<std::string, double>>{{"FV2", 0.0}, {"FS2", 0.0}}));
    EXPECT_EQ(m.effects[2].second, "sign(QP1)*exp(-(QP1/0.05)^2)");  // the default Stribeck velocity
  }
}

TEST_F(BrokenRobot, PrismaticJointsTakePrismaticUnits) {
  start_from("stanford_rrp");  // joint 3 is prismatic; robot.yaml ends with `variants:` (rigid)
  std::ofstream(dir_ / "robot.yaml", std::ios::app)
      << "  gap:\n    effects:\n      offset: [1, 3]\n      viscous_asymmetry: [3]\n";
  RobotModel r = load_robot(dir_.string());
  const Generation gen = generate_robot(r);
  ASSERT_EQ(gen.models.size(), 3u);  // full, rigid, gap
  const auto& ps = gen.models[2].identified;
  ASSERT_GE(ps.size(), 3u);
  const std::vector<ParameterRef> added(ps.end() - 3, ps.end());
  EXPECT_EQ(names_of(added), (std::vector<std::string>{"OFF1", "OFF3", "FVA3"}));
  EXPECT_EQ(added[0].unit, "N*m");
  EXPECT_EQ(added[1].unit, "N");
  EXPECT_EQ(added[2].unit, "N*s/m");
}

TEST_F(BrokenRobot, UnknownEffect) {
  add_variants("  bad:\n    effects:\n      backlash: [1]\n");
  expect_error(R"(robot\.yaml:31:7: error: variant bad: unknown effect 'backlash' \(known effects: coulomb, )"
               R"(inertia_products, offset, stribeck, viscous_asymmetry, position_harmonics, smooth_coulomb, )"
               R"(tustin_stribeck\))");
}

TEST_F(BrokenRobot, EffectJointOutOfRange) {
  add_variants("  bad:\n    effects:\n      offset: [1, 3]\n");
  expect_error(
      R"(robot\.yaml:31:19: error: variant bad, effect offset: joint 3 is out of range \(the robot has 2 joints\))");
}

TEST_F(BrokenRobot, EffectJointMustBeAWholeNumberFromOne) {
  add_variants("  bad:\n    effects:\n      offset: [0]\n  worse:\n    effects:\n      coulomb: [1.5]\n");
  expect_error(R"(robot\.yaml:31:16: error: variant bad, effect offset: joint 0 is out of range \(at least 1\))");
  replace("robot.yaml", "offset: [0]", "offset: [1]");
  expect_error(R"(robot\.yaml:34:17: error: variant worse, effect coulomb: joint must be a whole number, not '1\.5')");
}

TEST_F(BrokenRobot, EffectKeyTwice) {
  add_variants("  bad:\n    effects:\n      offset: [1]\n      offset: [2]\n");
  expect_error(R"(robot\.yaml:32:7: error: variant bad: effect offset appears twice)");
}

TEST_F(BrokenRobot, EffectJointTwice) {
  add_variants("  bad:\n    effects:\n      viscous_asymmetry: [2, 2]\n");
  expect_error(R"(robot\.yaml:31:30: error: variant bad, effect viscous_asymmetry: duplicate joint 2)");
}

TEST_F(BrokenRobot, StribeckVelocityMustBePositive) {
  add_variants("  bad:\n    effects:\n      stribeck: {joints: [1], velocity: 0}\n");
  expect_error(R"(robot\.yaml:31:41: error: variant bad, effect stribeck: the Stribeck velocity must be positive)");
}

TEST_F(BrokenRobot, SmoothCoulombVelocityMustBePositive) {
  add_variants("  bad:\n    effects:\n      smooth_coulomb: {joints: [1], velocity: -0.1}\n");
  expect_error(
      R"(robot\.yaml:31:47: error: variant bad, effect smooth_coulomb: the velocity scale of tanh\(qd/v\) must be positive)");
}

TEST_F(BrokenRobot, SmoothCoulombTakesAVelocityPerJoint) {
  // dynid diagnose selects a tanh width per joint: a variant keeps each.
  add_variants(
      "  widths:\n    fixed: {\"FS*\": 0}\n    effects:\n      smooth_coulomb: {joints: [2, 1], velocity: [0.05, "
      "0.02]}\n");
  RobotModel r = load_robot(dir_.string());
  const Generation gen = generate_robot(r);
  ASSERT_EQ(gen.models.size(), 3u);
  const ModelSummary& m = gen.models[2];
  ASSERT_EQ(m.effects.size(), 2u);
  EXPECT_EQ(m.effects[0], (std::pair<std::string, std::string>{"FC1", "tanh(QP1/0.02)"}));
  EXPECT_EQ(m.effects[1], (std::pair<std::string, std::string>{"FC2", "tanh(QP2/0.05)"}));
}

TEST_F(BrokenRobot, SmoothCoulombVelocitiesOnePerJoint) {
  add_variants("  bad:\n    effects:\n      smooth_coulomb: {joints: [1, 2], velocity: [0.05]}\n");
  expect_error(
      R"(robot\.yaml:31:50: error: variant bad, effect smooth_coulomb: a list of velocities needs one per joint \(1 for 2 joints\))");
}

TEST_F(BrokenRobot, OneCoulombTermPerJoint) {
  add_variants("  bad:\n    effects:\n      coulomb: [2]\n      smooth_coulomb: {joints: [2], velocity: 0.03}\n");
  expect_error(R"(robot\.yaml:32:[0-9]+: error: variant bad: joint 2 has both coulomb and smooth_coulomb)");
}

TEST_F(BrokenRobot, HarmonicOrderMustBeAtLeastOne) {
  add_variants("  bad:\n    effects:\n      position_harmonics: {joints: [1], orders: [1, 0]}\n");
  expect_error(
      R"(robot\.yaml:31:53: error: variant bad, effect position_harmonics: order 0 is out of range \(at least 1\))");
}

TEST_F(BrokenRobot, HarmonicsNeedOrders) {
  add_variants("  bad:\n    effects:\n      position_harmonics: {joints: [1]}\n");
  expect_error(R"(robot\.yaml:31:27: error: variant bad, effect position_harmonics needs 'orders')");
}

TEST_F(BrokenRobot, EffectOnALinkWithoutSuchParameters) {
  add_variants("  bad:\n    effects:\n      inertia_products: [1]\n");  // planar2r has no XY, XZ, YZ
  expect_error(R"(robot\.yaml:31:26: error: variant bad: effect inertia_products on link 1: the model has no such )"
               R"(base parameter \(XY1, XZ1, YZ1\))");
}

TEST_F(BrokenRobot, CoulombOfAJointWithoutFS) {
  start_from("crane_x7_reduced");  // OpenSYMORO's reduced files: no Coulomb friction at all
  std::ofstream(dir_ / "robot.yaml", std::ios::app) << "variants:\n  gap:\n    effects:\n      coulomb: [3]\n";
  expect_error(R"(robot\.yaml:27:17: error: variant gap: effect coulomb on joint 3: the model has no such )"
               R"(base parameter \(FS3\))");
}

TEST_F(BrokenRobot, UnknownBaseVariant) {
  add_variants("  bad:\n    base: reduced\n");
  expect_error(R"(robot\.yaml:30:11: error: variant bad: unknown base variant 'reduced' \(variants: effects, bad\))");
}

TEST_F(BrokenRobot, BaseChainCycle) {
  add_variants("  one:\n    base: two\n  two:\n    base: three\n  three:\n    base: one\n");
  expect_error(R"(robot\.yaml:34:11: error: variant three: the base chain one -> two -> three -> one is a cycle)");
}

TEST_F(BrokenRobot, VariantIsItsOwnBase) {
  add_variants("  self:\n    base: self\n");
  expect_error(R"(robot\.yaml:30:11: error: variant self: the base chain self -> self is a cycle)");
}

TEST_F(BrokenRobot, EffectAlreadyInTheBaseVariant) {
  add_variants("  more:\n    base: effects\n    effects:\n      offset: [2]\n");
  expect_error(
      R"(robot\.yaml:32:16: error: variant more: effect offset on joint 2 is already in its base variant 'effects')");
}

TEST_F(BrokenRobot, EffectsMustBeAMap) {
  add_variants("  bad:\n    effects: [offset]\n");
  expect_error(R"(robot\.yaml:30:14: error: variant bad: 'effects' must map effect names)");
}

TEST_F(BrokenRobot, EffectParameterNameClashes) {
  // A geometric constant named like the parameter an offset of joint 2 adds.
  replace("robot.yaml", "  G3: 9.80665     # m/s^2\n", "  G3: 9.80665     # m/s^2\n  OFF2: 1.0\n");
  expect_error(R"(robot\.yaml:19:1: error: variant effects: the effect parameter OFF2 is already a name of the model)");
}

TEST(Generation, IsReproducible) {
  RobotModel a = load_robot(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7");
  RobotModel b = load_robot(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7");
  const Generation ga = generate_robot(a), gb = generate_robot(b);
  ASSERT_EQ(ga.files.size(), gb.files.size());
  for (std::size_t i = 0; i < ga.files.size(); ++i) {
    EXPECT_EQ(ga.files[i].path, gb.files[i].path);
    EXPECT_EQ(ga.files[i].content, gb.files[i].content) << ga.files[i].path;
  }
  // The full model, reduced (the paper's 39) and reduced_diagnosed (39 + OFF5, FC2, FC4).
  ASSERT_EQ(ga.models.size(), 3u);
  EXPECT_EQ(ga.models[0].identified.size(), 65u);
  EXPECT_EQ(ga.models[1].identified.size(), 39u);
  EXPECT_EQ(ga.models[2].identified.size(), 42u);
}
