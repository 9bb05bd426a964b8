// Tests of the OpenSYMORO grammar: every real file under robots/, hand-checked values of the
// planar 2R model, operator precedence, positions, and the errors (with their exact locations)
// for malformed input.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "symoro/grammar/evaluate.hpp"
#include "symoro/grammar/parser.hpp"

namespace fs = std::filesystem;
using namespace symoro::grammar;
using Kind = Expr::Kind;

namespace {

const fs::path kRobots = SYMORO_ROBOTS_DIR;
const std::vector<std::string> kModelFiles = {"dim.txt", "ddm.txt", "inm.txt", "idm.txt",
                                              "ccg.txt", "fgm.txt", "jac.txt", "regp.txt"};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<fs::path> robot_dirs() {
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(kRobots))
    if (entry.is_directory()) dirs.push_back(entry.path());
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

const Equation& find_equation(const ModelFile& file, const std::string& name) {
  for (const auto& eq : file.equations)
    if (eq.name == name) return eq;
  throw std::runtime_error("no equation " + name + " in " + file.path);
}

// Every node of a parsed expression carries a position on `line` at or after `column`.
void expect_positions(const Expr& e, int line, int column) {
  EXPECT_EQ(e.at.line, line);
  EXPECT_GE(e.at.column, column);
  for (const Expr& arg : e.args) expect_positions(arg, line, column);
}

double value(const std::string& text, const Bindings& symbols = {}) {
  return evaluate(parse_expression(text, "test"), symbols);
}

// Runs `parse` and checks that it throws a ParseError at `line`:`column` with `message`.
void expect_error(const std::function<void()>& parse, int line, int column, const std::string& message) {
  try {
    parse();
    ADD_FAILURE() << "no error; expected " << line << ":" << column << ": " << message;
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.column(), column) << e.what();
    EXPECT_EQ(e.message(), message) << e.what();
  }
}

void expect_model_error(const std::string& text, int line, int column, const std::string& message) {
  expect_error([&] { parse_model_file(text, "model.txt"); }, line, column, message);
}

void expect_par_error(const std::string& text, int line, int column, const std::string& message) {
  expect_error([&] { parse_par_file(text, "robot.par"); }, line, column, message);
}

void expect_expr_error(const std::string& text, int line, int column, const std::string& message) {
  expect_error([&] { parse_expression(text, "expr"); }, line, column, message);
}

// A small model file whose equation section is `equations` (each line as given).
std::string model_with(const std::string& equations) {
  return "Title\n\nGeometric parameters\nj       ant     theta\n1       0       th1\n\n"
         "Equations:\n" +
         equations + "*=*\n";
}

// Model files of the real robots.

TEST(RealFiles, EveryModelFileParses) {
  int files = 0;
  for (const auto& dir : robot_dirs()) {
    for (const auto& name : kModelFiles) {
      const fs::path path = dir / name;
      SCOPED_TRACE(path.string());
      const ModelFile file = read_model_file(path.string());
      ++files;
      const auto lines = split_lines(read_text(path));

      EXPECT_EQ(file.path, path.string());
      EXPECT_FALSE(file.title.empty());
      ASSERT_FALSE(file.tables.empty());
      EXPECT_EQ(file.tables.front().title, "Geometric parameters");
      EXPECT_EQ(file.tables.front().columns.size(), 10u);
      for (const auto& table : file.tables) {
        EXPECT_TRUE(table.columns.front() == "j" || table.columns.front() == "axis");
        EXPECT_EQ(lines.at(table.at.line - 1), table.title);
        for (const auto& row : table.rows) {
          EXPECT_EQ(row.cells.size(), table.columns.size());
          for (const auto& cell : row.cells) expect_positions(cell, row.at.line, 1);
        }
      }
      EXPECT_EQ(lines.at(file.equations_at.line - 1), "Equations:");

      // One equation per line ending with ';', each at the start of its line.
      std::size_t semicolons = 0;
      for (const auto& line : lines)
        if (!line.empty() && line.back() == ';') ++semicolons;
      EXPECT_EQ(file.equations.size(), semicolons);
      for (const auto& eq : file.equations) {
        EXPECT_EQ(eq.at.column, 1);
        EXPECT_EQ(lines.at(eq.at.line - 1).rfind(eq.name + " = ", 0), 0u) << eq.name;
        expect_positions(eq.value, eq.at.line, static_cast<int>(eq.name.size()) + 4);
      }

      if (name == "regp.txt") {
        EXPECT_EQ(file.grouped_title, "Grouped inertial parameters");
        ASSERT_EQ(file.grouped_tables.size(), 2u);
        EXPECT_EQ(file.grouped_tables[0].title, "Geometric parameters");
        EXPECT_EQ(file.grouped_tables[1].title, "Dynamic inertia parameters");
      } else {
        EXPECT_TRUE(file.grouped_title.empty());
        EXPECT_TRUE(file.grouped_tables.empty());
      }
    }
  }
  EXPECT_EQ(files, 8 * static_cast<int>(robot_dirs().size()));  // every robot's eight model files
}

TEST(RealFiles, EveryParFileParses) {
  int files = 0;
  for (const auto& dir : robot_dirs()) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".par") continue;
      SCOPED_TRACE(entry.path().string());
      const ParFile par = read_par_file(entry.path().string());
      ++files;
      EXPECT_EQ(par.robot_name, entry.path().stem().string());

      std::size_t assignments = 0;
      for (const auto& line : split_lines(read_text(entry.path())))
        if (line.find(" = ") != std::string::npos && line.rfind("(*", 0) != 0) ++assignments;
      EXPECT_EQ(par.entries.size(), assignments);

      std::set<std::string> names;
      for (const auto& e : par.entries) names.insert(e.name);
      for (const char* key : {"NL", "NJ", "NF", "Type", "ant", "theta", "G", "Z"})
        EXPECT_EQ(names.count(key), 1u) << key;
      for (const auto& e : par.entries) {
        EXPECT_EQ(e.at.column, 1);
        if (e.name == "Z") {
          EXPECT_EQ(e.values.size(), 16u);
        }
        if (e.name == "G") {
          EXPECT_EQ(e.values.size(), 3u);
        }
        if (e.name == "NL") {
          EXPECT_FALSE(e.is_list);
        }
        if (e.name == "is_floating") {
          ASSERT_EQ(e.values.size(), 1u);
          EXPECT_EQ(e.values[0].kind, Kind::Symbol);
          EXPECT_EQ(e.values[0].name, "False");
        }
      }
    }
  }
  EXPECT_EQ(files, 2 * static_cast<int>(robot_dirs().size()));  // <robot>.par and <robot>_base.par
}

TEST(Planar2r, DimStructure) {
  const ModelFile dim = read_model_file((kRobots / "planar2r" / "dim.txt").string());
  EXPECT_EQ(dim.title, std::vector<std::string>{"Dynamic Identification Model (Newton-Euler method)"});
  ASSERT_EQ(dim.tables.size(), 4u);
  EXPECT_EQ(dim.tables[0].title, "Geometric parameters");
  EXPECT_EQ(dim.tables[1].title, "Dynamic inertia parameters");
  EXPECT_EQ(dim.tables[2].title, "External forces and joint parameters");
  EXPECT_EQ(dim.tables[3].title, "Base velocity parameters");
  EXPECT_EQ(dim.tables[0].at.line, 3);
  EXPECT_EQ(dim.tables[0].rows.size(), 2u);
  EXPECT_EQ(dim.tables[1].columns.size(), 12u);
  EXPECT_EQ(dim.tables[2].columns.size(), 14u);

  // Geometric row 2: j=2, ant=1, d=L1, theta=th2.
  const auto& geo = dim.tables[0];
  EXPECT_EQ(geo.columns[7], "d");
  const auto& row2 = geo.rows[1];
  EXPECT_EQ(row2.at.line, 6);
  EXPECT_EQ(row2.cells[0].number, 2.0);
  EXPECT_EQ(row2.cells[7].name, "L1");
  EXPECT_EQ(row2.cells[7].at.column, 57);
  EXPECT_EQ(row2.cells[8].name, "th2");

  // Base velocity: axis Y, G = -G3.
  const auto& base = dim.tables[3];
  EXPECT_EQ(base.columns, (std::vector<std::string>{"axis", "W0", "WP0", "V0", "VP0", "G"}));
  ASSERT_EQ(base.rows.size(), 3u);
  EXPECT_EQ(base.rows[1].cells[0].name, "Y");
  const Expr& g = base.rows[1].cells[5];
  ASSERT_EQ(g.kind, Kind::Negate);
  EXPECT_EQ(g.args[0].name, "G3");

  EXPECT_EQ(dim.equations_at.line, 24);
  ASSERT_EQ(dim.equations.size(), 132u);
  const Equation& first = dim.equations.front();
  EXPECT_EQ(first.name, "C1");
  EXPECT_EQ(first.at.line, 25);
  EXPECT_EQ(first.value.kind, Kind::Call);
  EXPECT_EQ(first.value.name, "cos");
  ASSERT_EQ(first.value.args.size(), 1u);
  EXPECT_EQ(first.value.args[0].kind, Kind::Symbol);
  EXPECT_EQ(first.value.args[0].name, "th1");
  EXPECT_EQ(first.value.args[0].at.column, 10);
}

TEST(Planar2r, EquationCounts) {
  const std::vector<std::pair<std::string, std::size_t>> counts = {{"ccg.txt", 28}, {"ddm.txt", 130}, {"dim.txt", 132},
                                                                   {"fgm.txt", 16}, {"idm.txt", 32},  {"inm.txt", 16},
                                                                   {"jac.txt", 21}, {"regp.txt", 14}};
  for (const auto& [name, n] : counts)
    EXPECT_EQ(read_model_file((kRobots / "planar2r" / name).string()).equations.size(), n) << name;
}

TEST(Planar2r, JacobianAndGeometry) {
  const ModelFile jac = read_model_file((kRobots / "planar2r" / "jac.txt").string());
  EXPECT_EQ(jac.title,
            (std::vector<std::string>{"Jacobian matrix for frame 2", "Projection frame 0, intermediate frame 2"}));
  EXPECT_EQ(jac.tables.size(), 1u);
  const double th1 = 0.3, th2 = -1.1, L1 = 0.7;
  auto v = run_equations(jac.equations, {{"th1", th1}, {"th2", th2}, {"L1", L1}});
  EXPECT_DOUBLE_EQ(v["J11"], -L1 * std::sin(th1));
  EXPECT_DOUBLE_EQ(v["J21"], L1 * std::cos(th1));
  EXPECT_DOUBLE_EQ(v["J62"], 1.0);

  const ModelFile fgm = read_model_file((kRobots / "planar2r" / "fgm.txt").string());
  v = run_equations(fgm.equations, {{"th1", th1}, {"th2", th2}, {"L1", L1}});
  EXPECT_NEAR(v["T0T211"], std::cos(th1 + th2), 1e-15);
  EXPECT_NEAR(v["T0T221"], std::sin(th1 + th2), 1e-15);
  EXPECT_NEAR(v["T0T212"], -std::sin(th1 + th2), 1e-15);
  EXPECT_DOUBLE_EQ(v["T0T214"], L1 * std::cos(th1));
  EXPECT_DOUBLE_EQ(v["T0T224"], L1 * std::sin(th1));
  EXPECT_DOUBLE_EQ(v["T0T233"], 1.0);
}

Bindings planar2r_point() {
  return {{"th1", 0.4},  {"th2", -0.9}, {"QP1", 1.3},  {"QP2", -0.6}, {"QDP1", 0.5}, {"QDP2", 2.0}, {"L1", 0.8},
          {"G3", 9.81},  {"ZZR1", 1.7}, {"ZZ2", 0.35}, {"MXR1", 2.1}, {"MY1", -0.2}, {"MX2", 0.45}, {"MY2", 0.07},
          {"IA2", 0.02}, {"FS1", 0.3},  {"FS2", 0.25}, {"FV1", 0.11}, {"FV2", 0.09}};
}

TEST(Planar2r, InertiaMatrixByHand) {
  const ModelFile inm = read_model_file((kRobots / "planar2r" / "inm.txt").string());
  Bindings in = planar2r_point();
  const auto v = run_equations(inm.equations, in);
  const double c2 = std::cos(in["th2"]), s2 = std::sin(in["th2"]);
  const double coupling = in["L1"] * (c2 * in["MX2"] - s2 * in["MY2"]);
  EXPECT_NEAR(v.at("A11"), in["ZZR1"] + in["ZZ2"] + 2 * coupling, 1e-12);
  EXPECT_NEAR(v.at("A21"), in["ZZ2"] + coupling, 1e-12);
  EXPECT_NEAR(v.at("A22"), in["ZZ2"] + in["IA2"], 1e-12);
}

TEST(Planar2r, GravityTorquesByHand) {
  // At rest with no friction, GAM = dV/dq with V = G3 * (height of the first moments):
  // V = G3 * (MXR1 S1 + MY1 C1 + MX2 S12 + MY2 C12).
  const ModelFile idm = read_model_file((kRobots / "planar2r" / "idm.txt").string());
  Bindings in = planar2r_point();
  for (const char* zero : {"QP1", "QP2", "QDP1", "QDP2", "FS1", "FS2", "FV1", "FV2"}) in[zero] = 0;
  const auto v = run_equations(idm.equations, in);
  const double th1 = in["th1"], th12 = in["th1"] + in["th2"], g = in["G3"];
  const double gam2 = g * (in["MX2"] * std::cos(th12) - in["MY2"] * std::sin(th12));
  const double gam1 = g * (in["MXR1"] * std::cos(th1) - in["MY1"] * std::sin(th1)) + gam2;
  EXPECT_NEAR(v.at("GAM1"), gam1, 1e-12);
  EXPECT_NEAR(v.at("GAM2"), gam2, 1e-12);
}

TEST(Planar2r, InverseDynamicsIsInertiaTimesAccelerationPlusCcg) {
  Bindings in = planar2r_point();
  const auto model = [](const char* name) { return read_model_file((kRobots / "planar2r" / name).string()); };
  const auto idm = run_equations(model("idm.txt").equations, in);
  const auto inm = run_equations(model("inm.txt").equations, in);
  const auto ccg = run_equations(model("ccg.txt").equations, in);
  const double q1 = in["QDP1"], q2 = in["QDP2"];
  EXPECT_NEAR(idm.at("GAM1"), inm.at("A11") * q1 + inm.at("A21") * q2 + ccg.at("GAM1"), 1e-12);
  EXPECT_NEAR(idm.at("GAM2"), inm.at("A21") * q1 + inm.at("A22") * q2 + ccg.at("GAM2"), 1e-12);
}

TEST(Planar2r, GroupedParameters) {
  const ModelFile regp = read_model_file((kRobots / "planar2r" / "regp.txt").string());
  EXPECT_EQ(regp.title, std::vector<std::string>{"Base Inertial Parameters equations"});
  EXPECT_EQ(regp.tables.size(), 4u);
  EXPECT_EQ(regp.grouped_title, "Grouped inertial parameters");
  ASSERT_EQ(regp.grouped_tables.size(), 2u);
  EXPECT_EQ(regp.grouped_tables[0].at.line, 43);
  EXPECT_EQ(regp.grouped_tables[1].rows[0].cells[6].name, "ZZR1");

  const Bindings in = {{"th1", 0.1}, {"th2", 0.2}, {"L1", 0.8}, {"M1", 3.0},  {"M2", 1.5},  {"MX1", 0.4}, {"IA1", 0.01},
                       {"ZZ1", 0.2}, {"XX1", 0},   {"XX2", 0},  {"YY1", 0.6}, {"YY2", 0.3}, {"MZ1", 0},   {"MZ2", 0}};
  const auto v = run_equations(regp.equations, in);
  EXPECT_DOUBLE_EQ(v.at("ZZR1"), 0.01 + 0.64 * 1.5 + 0.2);
  EXPECT_DOUBLE_EQ(v.at("MXR1"), 0.8 * 1.5 + 0.4);
  EXPECT_DOUBLE_EQ(v.at("MR1"), 4.5);
  const Equation& ms = find_equation(regp, "LamMS412");  // 2*C2*L1
  EXPECT_DOUBLE_EQ(evaluate(ms.value, v), 2 * std::cos(0.2) * 0.8);
}

TEST(Planar2r, ParFile) {
  const ParFile par = read_par_file((kRobots / "planar2r" / "planar2r.par").string());
  EXPECT_EQ(par.robot_name, "planar2r");
  ASSERT_EQ(par.entries.size(), 45u);
  EXPECT_EQ(par.entries[0].name, "NL");
  EXPECT_EQ(par.entries[0].at.line, 2);
  EXPECT_FALSE(par.entries[0].is_list);
  EXPECT_EQ(par.entries[0].values[0].number, 2.0);
  for (const auto& e : par.entries) {
    if (e.name == "d") {
      EXPECT_TRUE(e.is_list);
      ASSERT_EQ(e.values.size(), 2u);
      EXPECT_EQ(e.values[1].name, "L1");
      EXPECT_EQ(e.values[1].at.column, 8);
    }
    if (e.name == "G") {
      ASSERT_EQ(e.values.size(), 3u);
      EXPECT_EQ(e.values[1].kind, Kind::Negate);
    }
  }
}

TEST(RealFiles, Rx90AlphaValues) {
  const ParFile par = read_par_file((kRobots / "rx90" / "rx90.par").string());
  for (const auto& e : par.entries) {
    if (e.name != "alpha") continue;
    ASSERT_EQ(e.values.size(), 6u);
    const double expected[] = {0, M_PI / 2, 0, -M_PI / 2, M_PI / 2, -M_PI / 2};
    for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(evaluate(e.values[i], {}), expected[i]);
  }
}

// Expressions.

TEST(Expressions, Precedence) {
  EXPECT_EQ(value("-x**2", {{"x", 3}}), -9);
  EXPECT_EQ(value("2**3**2"), 512);
  EXPECT_EQ(value("(2**3)**2"), 64);
  EXPECT_EQ(value("a-b-c", {{"a", 10}, {"b", 3}, {"c", 2}}), 5);
  EXPECT_EQ(value("a/b/c", {{"a", 12}, {"b", 3}, {"c", 2}}), 2);
  EXPECT_EQ(value("2**-1"), 0.5);
  EXPECT_EQ(value("-2**-2"), -0.25);
  EXPECT_EQ(value("1+2*3"), 7);
  EXPECT_EQ(value("2*3**2"), 18);
  EXPECT_EQ(value("-3*-2"), 6);
  EXPECT_EQ(value("a--b", {{"a", 1}, {"b", 2}}), 3);
  EXPECT_EQ(value("+4 - +1"), 3);
  EXPECT_EQ(value("(1+2)*(3-4)/2"), -1.5);
  EXPECT_DOUBLE_EQ(value("-pi/2"), -M_PI / 2);
  EXPECT_DOUBLE_EQ(value("sin(x)**2 + cos(x)**2", {{"x", 0.7}}), 1.0);
}

TEST(Expressions, TreeShape) {
  const Expr e = parse_expression("-x**2", "t");
  ASSERT_EQ(e.kind, Kind::Negate);
  ASSERT_EQ(e.args[0].kind, Kind::Power);
  EXPECT_EQ(e.args[0].args[0].name, "x");

  const Expr s = parse_expression("a-b-c", "t");
  ASSERT_EQ(s.kind, Kind::Subtract);
  EXPECT_EQ(s.args[0].kind, Kind::Subtract);
  EXPECT_EQ(s.args[1].name, "c");

  const Expr p = parse_expression("a**b**c", "t");
  ASSERT_EQ(p.kind, Kind::Power);
  EXPECT_EQ(p.args[0].name, "a");
  EXPECT_EQ(p.args[1].kind, Kind::Power);

  const Expr c = parse_expression("f(a, b+1, g())", "t");
  ASSERT_EQ(c.kind, Kind::Call);
  EXPECT_EQ(c.name, "f");
  ASSERT_EQ(c.args.size(), 3u);
  EXPECT_EQ(c.args[1].kind, Kind::Add);
  EXPECT_EQ(c.args[2].kind, Kind::Call);
  EXPECT_TRUE(c.args[2].args.empty());
}

TEST(Expressions, Numbers) {
  EXPECT_EQ(value("1.5e-3"), 1.5e-3);
  EXPECT_EQ(value("2E+2"), 200);
  EXPECT_EQ(value(".25"), 0.25);
  EXPECT_EQ(value("5."), 5);
  EXPECT_EQ(value("007"), 7);
  EXPECT_EQ(value("1e308"), 1e308);
}

TEST(Expressions, Positions) {
  const Expr e = parse_expression("a + (b*c) - -d", "t");
  ASSERT_EQ(e.kind, Kind::Subtract);
  EXPECT_EQ(e.at.column, 1);
  const Expr& sum = e.args[0];
  EXPECT_EQ(sum.args[1].at.column, 5);          // the '(' of (b*c)
  EXPECT_EQ(sum.args[1].args[1].at.column, 8);  // c
  EXPECT_EQ(e.args[1].at.column, 13);           // the unary '-'
  EXPECT_EQ(e.args[1].args[0].at.column, 14);   // d

  const Expr multi = parse_expression("  x\n  * y\r\n", "t");
  EXPECT_EQ(multi.at.line, 1);
  EXPECT_EQ(multi.at.column, 3);
  EXPECT_EQ(multi.args[1].at.line, 2);
  EXPECT_EQ(multi.args[1].at.column, 5);
}

TEST(Expressions, NestingLimit) {
  const auto nested = [](int n) { return std::string(n, '(') + "x" + std::string(n, ')'); };
  EXPECT_EQ(parse_expression(nested(kMaxExpressionDepth), "t").kind, Kind::Symbol);
  expect_expr_error(nested(kMaxExpressionDepth + 1), 1, kMaxExpressionDepth + 1, "nesting deeper than 256 levels");

  EXPECT_EQ(value(std::string(kMaxExpressionDepth, '-') + "3"), 3);
  expect_expr_error(std::string(kMaxExpressionDepth + 1, '-') + "3", 1, 257, "nesting deeper than 256 levels");

  std::string power;
  for (int i = 0; i < kMaxExpressionDepth; ++i) power += "1**";
  EXPECT_EQ(value(power + "1"), 1);
  expect_expr_error(power + "1**1", 1, 3 * kMaxExpressionDepth + 2, "nesting deeper than 256 levels");
}

TEST(Expressions, HugeInputsFailFast) {
  const auto start = std::chrono::steady_clock::now();
  expect_expr_error(std::string(100000, '('), 1, 257, "nesting deeper than 256 levels");
  expect_expr_error(std::string(100000, '-') + "x", 1, 257, "nesting deeper than 256 levels");
  std::string powers;
  for (int i = 0; i < 100000; ++i) powers += "x**";
  expect_expr_error(powers + "x", 1, 3 * 256 + 2, "nesting deeper than 256 levels");
  std::string calls;
  for (int i = 0; i < 100000; ++i) calls += "f(";
  expect_expr_error(calls, 1, 2 * 256 + 2, "nesting deeper than 256 levels");
  // A flat chain nests nothing, but its tree is as deep as it is long.
  std::string chain = "x";
  for (int i = 0; i < 100000; ++i) chain += "+x";
  expect_expr_error(chain, 1, 2 * 1024 + 1, "expression more than 1024 operations deep");
  expect_expr_error(std::string(1000000, '9'), 1, 1, "number out of range");
  EXPECT_EQ(parse_expression(std::string(1000000, 'a'), "t").name.size(), 1000000u);
  // The same inside a model file and a .par file.
  expect_model_error(model_with("A = " + std::string(100000, '(') + ";\n"), 8, 261, "nesting deeper than 256 levels");
  expect_par_error("x = {" + std::string(100000, '-') + "}\n", 1, 262, "nesting deeper than 256 levels");
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_LT(std::chrono::duration_cast<std::chrono::milliseconds>(elapsed).count(), 2000);
}

// Input variations that must parse.

TEST(Layout, CrlfTabsTrailingSpaceAndNoFinalNewline) {
  const std::string text = "Title\r\n\r\nT\r\n\tj\taxis2\t\r\n\t1\t-x \r\n\r\nEquations:  \r\n\tA =\tb ;  \r\n*=*";
  const ModelFile file = parse_model_file(text, "crlf.txt");
  ASSERT_EQ(file.tables.size(), 1u);
  EXPECT_EQ(file.tables[0].title, "T");
  EXPECT_EQ(file.tables[0].columns, (std::vector<std::string>{"j", "axis2"}));
  ASSERT_EQ(file.tables[0].rows.size(), 1u);
  EXPECT_EQ(file.tables[0].rows[0].at.column, 2);
  EXPECT_EQ(file.tables[0].rows[0].cells[1].kind, Kind::Negate);
  ASSERT_EQ(file.equations.size(), 1u);
  EXPECT_EQ(file.equations[0].at.line, 8);
  EXPECT_EQ(file.equations[0].at.column, 2);
  EXPECT_EQ(file.equations[0].value.at.column, 6);
}

TEST(Layout, TablesWithoutBlankLinesAndEmptyEquations) {
  const std::string text =
      "A title\nSecond title line\nFirst table\nj a\n1 2\nSecond table\naxis b\nX 3\n"
      "Equations:\n\n*=*\n";
  const ModelFile file = parse_model_file(text, "m.txt");
  EXPECT_EQ(file.title.size(), 2u);
  ASSERT_EQ(file.tables.size(), 2u);
  EXPECT_EQ(file.tables[0].rows.size(), 1u);
  EXPECT_EQ(file.tables[1].title, "Second table");
  EXPECT_TRUE(file.equations.empty());
}

TEST(Layout, ParCommentsAndSpacing) {
  const ParFile par = parse_par_file(
      "(* a comment\n spanning lines *)\n  x = { 1 , -a }  (* trailing *)\r\ny=z\r\n"
      "(*Robotname='r2'*)\nempty = {}\n",
      "p.par");
  EXPECT_EQ(par.robot_name, "r2");
  ASSERT_EQ(par.entries.size(), 3u);
  EXPECT_EQ(par.entries[0].at.line, 3);
  EXPECT_EQ(par.entries[0].at.column, 3);
  EXPECT_EQ(par.entries[0].values.size(), 2u);
  EXPECT_EQ(par.entries[1].values[0].name, "z");
  EXPECT_TRUE(par.entries[2].is_list);
  EXPECT_TRUE(par.entries[2].values.empty());
}

// Errors: exact position and message.

TEST(Errors, Equations) {
  expect_model_error(model_with("A = b\n"), 8, 6, "expected ';' at the end of the equation");
  expect_model_error(model_with("A = ;\n"), 8, 5, "expected an expression after '='");
  expect_model_error(model_with("A = b;\nB = c @ d;\n"), 9, 7, "unexpected character '@'");
  expect_model_error(model_with("A = (b + c;\n"), 8, 11, "expected ')'");
  expect_model_error(model_with("A = b + c);\n"), 8, 10, "expected ';' at the end of the equation");
  expect_model_error(model_with("A = cos(b;\n"), 8, 10, "expected ')' after the function arguments");
  expect_model_error(model_with("A b;\n"), 8, 3, "expected '=' after the name");
  expect_model_error(model_with("2A = b;\n"), 8, 1, "expected an equation 'NAME = expression;' or '*=*'");
  expect_model_error(model_with("A = b; c\n"), 8, 8, "expected the end of the line after ';'");
  expect_model_error(model_with("A = b*;\n"), 8, 7, "expected an expression after '*'");
  expect_model_error(model_with("A = 1e400;\n"), 8, 5, "number out of range");
}

TEST(Errors, Tables) {
  const std::string head = "Title\n\nGeometric parameters\nj a b c d e f g h i\n";
  expect_model_error(head + "1 2 3 4 5 6 7 8 9\n\nEquations:\n*=*\n", 5, 18,
                     "row has 9 cells but the header has 10 columns");
  expect_model_error(head + "1 2 3 4 5 6 7 8 9 10 11\n\nEquations:\n*=*\n", 5, 22,
                     "row has 11 cells but the header has 10 columns");
  expect_model_error("T\nj a\n1 2)\n\nEquations:\n*=*\n", 3, 4, "expected a space between cells or the end of the row");
  expect_model_error("T\nj a\n1 -\n\nEquations:\n*=*\n", 3, 4, "expected an expression after '-'");
  expect_model_error("T\nj a 3b\n1 2\n\nEquations:\n*=*\n", 2, 5, "expected a column name");
  expect_model_error("T\nj a a\n\nEquations:\n*=*\n", 2, 5, "duplicate column 'a'");
  expect_model_error("T\nj a\n1 2\n\nstray text\n\nEquations:\n*=*\n", 5, 1,
                     "expected a table (a title line, then a header row starting with 'j' or "
                     "'axis') or 'Equations:'");
}

TEST(Errors, FileStructure) {
  expect_model_error("", 1, 1, "empty file");
  expect_model_error("\n  \r\n\t\n", 1, 1, "empty file");
  expect_model_error("Title\n\nT\nj a\n1 2\n", 5, 4, "missing 'Equations:' section");
  expect_model_error("Title\n\nEquations:\nA = b;\n\n", 4, 7, "missing '*=*' end marker");
  expect_model_error("Title\n*=*\n", 2, 1, "expected 'Equations:' before '*=*'");
  expect_model_error("Title\n\nEquations:\nA = b;\n*=*\nGrouped\n\nT\nj a\n1 2\n", 10, 4, "missing '*=*' end marker");
  expect_model_error("Title\n\nEquations:\n*=*\nG\nT\nj a\n*=*\nmore\n", 9, 1, "unexpected text after the final '*=*'");
  expect_model_error("Title\n\nEquations:\nA = b;\n*=*\nG\nH\n*=*\n", 7, 1,
                     "expected a table (a title line, then a header row starting with 'j' or "
                     "'axis') or '*=*'");
  expect_model_error(std::string("Ti\0tle\n", 7), 1, 3, "unexpected character '\\x00'");
  expect_model_error("Title\rMore\n", 1, 6, "unexpected character '\\x0D'");
}

TEST(Errors, ParFiles) {
  expect_par_error("NL = 2\nant = {0,1\n", 2, 11, "expected ',' or '}' in the list");
  expect_par_error("ant = {0,,1}\n", 1, 10, "expected a value after ','");
  expect_par_error("ant = {0 1}\n", 1, 10, "expected ',' or '}' in the list");
  expect_par_error("ant 3\n", 1, 5, "expected '=' after the name");
  expect_par_error("ant =\n", 1, 6, "expected a value after '='");
  expect_par_error("NL = 2;\n", 1, 7, "expected the end of the line after the value");
  expect_par_error("x = 1\n(* open\nNL = 2\n", 2, 1, "unterminated comment: expected '*)'");
  expect_par_error("x = #\n", 1, 5, "unexpected character '#'");
  expect_par_error(" \n", 1, 1, "empty file");
}

TEST(Errors, WhatShowsLineAndCaret) {
  try {
    parse_model_file(model_with("A = b;\n\tB = c @ d;\n"), "dir/idm.txt");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "dir/idm.txt");
    EXPECT_STREQ(e.what(), "dir/idm.txt:9:8: error: unexpected character '@'\n\tB = c @ d;\n\t      ^");
  }
  try {
    parse_expression("a +", "expr");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_STREQ(e.what(), "expr:1:4: error: expected an expression after '+'\na +\n   ^");
  }
}

TEST(Errors, MissingFile) {
  try {
    read_model_file("/nonexistent/dim.txt");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.message(), "cannot open file");
    EXPECT_STREQ(e.what(), "/nonexistent/dim.txt: error: cannot open file");
  }
  EXPECT_THROW(read_par_file("/nonexistent/robot.par"), ParseError);
  EXPECT_THROW(read_model_file(kRobots.string()), ParseError);  // a directory
}

TEST(Errors, Expressions) {
  expect_expr_error("", 1, 1, "expected an expression");
  expect_expr_error("a b", 1, 3, "expected an operator or the end of the expression");
  expect_expr_error("(a", 1, 3, "expected ')'");
  expect_expr_error("a)", 1, 2, "expected an operator or the end of the expression");
  expect_expr_error("f(a,)", 1, 5, "expected an argument after ','");
  expect_expr_error("a ** * b", 1, 6, "expected an expression after '**'");
  expect_expr_error("x\n+\n", 2, 2, "expected an expression after '+'");
  expect_expr_error("1e-400", 1, 1, "number out of range");
  expect_expr_error("a\xC3\xA9", 1, 2, "unexpected character '\\xC3'");
}

}  // namespace
