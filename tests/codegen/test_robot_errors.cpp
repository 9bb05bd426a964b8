// Bad robot folders get errors that name the file, the line and the problem; good ones load.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

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

  void replace(const std::string& file, const std::string& from, const std::string& to) {
    std::string text = read(dir_ / file);
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(dir_ / file) << text;
  }

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

TEST_F(BrokenRobot, VariantPatternThatMatchesNothing) {
  std::ofstream(dir_ / "robot.yaml", std::ios::app) << "variants:\n  light:\n    fixed: {\"XY*\": 0}\n";
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
  std::ofstream(dir_ / "robot.yaml", std::ios::app)
      << "variants:\n  frictionless:\n    fixed: {\"FS*\": 0, \"FV*\": 0}\n";
  RobotModel r = load_robot(dir_.string());
  const Generation gen = generate_robot(r);
  ASSERT_EQ(gen.models.size(), 2u);
  EXPECT_EQ(gen.models[1].name, "arm::frictionless");
  EXPECT_EQ(gen.models[1].identified.size(), 7u);
  EXPECT_EQ(gen.models[1].fixed.size(), 4u);
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
  EXPECT_EQ(ga.models.size(), 2u);
  EXPECT_EQ(ga.models[0].identified.size(), 65u);
  EXPECT_EQ(ga.models[1].identified.size(), 39u);
}
