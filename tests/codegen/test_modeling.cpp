// `symoroc model` against OpenSYMORO: on every robot folder that has OpenSYMORO's files, the
// models computed from the .par alone have the same base parameters (names, and the same
// combinations of standard parameters), and their inverse dynamics, Coriolis-gravity torques,
// inertia matrix, direct dynamics, identification model, geometric model and Jacobian agree
// with OpenSYMORO's at random states, with random physical standard parameters mapped through
// each model's own base_from_standard.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "../removed_at_exit.hpp"
#include "relative_difference.hpp"
#include "symoro/codegen/graph_evaluator.hpp"
#include "symoro/codegen/modeling.hpp"
#include "symoro/codegen/robot_model.hpp"

namespace symoro::codegen {
namespace {

namespace fs = std::filesystem;
const fs::path kRobots = SYMORO_ROBOTS_DIR;

fs::path par_of(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string f = e.path().filename().string();
    if (e.path().extension() == ".par" && f.find("_base.par") == std::string::npos) return e.path();
  }
  return {};
}

// The robot folder symoroc model writes, with the robot's robot.yaml copied in.
fs::path model_folder(const std::string& robot, int frame) {
  const fs::path src = kRobots / robot;
  const fs::path out = symoro::test::removed_at_exit("symoro_model_" + std::to_string(::getpid())) / robot;
  fs::create_directories(out);
  const fs::path par = par_of(src);
  fs::copy_file(par, out / par.filename(), fs::copy_options::overwrite_existing);
  fs::copy_file(src / "robot.yaml", out / "robot.yaml", fs::copy_options::overwrite_existing);
  ModelingOptions o;
  o.frame = frame;
  const Modeling m = model_from_par(par.string(), o);
  for (const auto& f : m.files) std::ofstream(out / f.name) << f.text;
  return out;
}

std::vector<NodeId> flat(const std::vector<std::vector<NodeId>>& m) {
  std::vector<NodeId> out;
  for (const auto& row : m) out.insert(out.end(), row.begin(), row.end());
  return out;
}

using test::relative_difference;

class ModelFromPar : public ::testing::TestWithParam<std::string> {};

TEST_P(ModelFromPar, MatchesOpenSymoro) {
  const std::string robot = GetParam();
  RobotModel ref = load_robot((kRobots / robot).string());
  // The frame OpenSYMORO's user chose for the geometric model (CRANE-X7: the wrist, 7 of 8).
  RobotModel ours = load_robot(model_folder(robot, ref.fgm_frame).string());
  EXPECT_EQ(ours.fgm_frame, ref.fgm_frame);
  ASSERT_EQ(ours.n, ref.n);

  // The same base parameters, in the same order.
  std::vector<std::string> ref_names, our_names;
  for (const auto& p : ref.base) ref_names.push_back(p.name);
  for (const auto& p : ours.base) our_names.push_back(p.name);
  EXPECT_EQ(our_names, ref_names);
  ASSERT_EQ(ours.base.size(), ref.base.size());

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Evaluator ref_base(ref.graph, ref.base_from_standard), our_base(ours.graph, ours.base_from_standard);
  auto models = [](RobotModel& m) {
    std::vector<NodeId> roots = m.idm;
    roots.insert(roots.end(), m.ccg.begin(), m.ccg.end());
    for (auto* part : {&m.inm, &m.fgm, &m.jac, &m.dim}) {
      const auto f = flat(*part);
      roots.insert(roots.end(), f.begin(), f.end());
    }
    roots.insert(roots.end(), m.ddm.begin(), m.ddm.end());
    return roots;
  };
  Evaluator ref_models(ref.graph, models(ref)), our_models(ours.graph, models(ours));
  for (int trial = 0; trial < 20; ++trial) {
    // Physical standard parameters: positive masses, centres of mass near the joints, inertia
    // tensors from positive principal moments, rotors and friction positive.
    std::map<std::string, double> standard;
    for (int j = 1; j <= ref.n; ++j) {
      const double m = 0.5 + 2 * std::abs(u(rng));
      const double c[3] = {0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)};
      const double I[3] = {0.01 + 0.02 * std::abs(u(rng)), 0.01 + 0.02 * std::abs(u(rng)),
                           0.01 + 0.02 * std::abs(u(rng))};
      const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
      const double J[3][3] = {{I[0] + m * (cc - c[0] * c[0]), -m * c[0] * c[1], -m * c[0] * c[2]},
                              {-m * c[0] * c[1], I[1] + m * (cc - c[1] * c[1]), -m * c[1] * c[2]},
                              {-m * c[0] * c[2], -m * c[1] * c[2], I[2] + m * (cc - c[2] * c[2])}};
      const std::map<std::string, double> value = {{"XX", J[0][0]},
                                                   {"XY", J[0][1]},
                                                   {"XZ", J[0][2]},
                                                   {"YY", J[1][1]},
                                                   {"YZ", J[1][2]},
                                                   {"ZZ", J[2][2]},
                                                   {"MX", m * c[0]},
                                                   {"MY", m * c[1]},
                                                   {"MZ", m * c[2]},
                                                   {"M", m},
                                                   {"IA", 0.05 * std::abs(u(rng))},
                                                   {"FV", 0.1 * std::abs(u(rng))},
                                                   {"FS", 0.1 * std::abs(u(rng))}};
      for (const auto& p : ref.standard)
        if (p.joint == j) standard[p.name] = value.at(p.family);
    }
    for (const auto& [k, v] : ref.spec.constants) standard[k] = v;
    const auto ref_b = ref_base(standard), our_b = our_base(standard);
    EXPECT_LT(relative_difference(ref_b, our_b), 1e-12) << robot << " base_from_standard, trial " << trial;

    std::map<std::string, double> at;
    for (std::size_t p = 0; p < ref.base.size(); ++p) at[ref.base[p].name] = ref_b[p];
    for (int j = 0; j < ref.n; ++j) {
      at[ref.q[j]] = 2 * u(rng);
      at[ref.qd[j]] = 2 * u(rng);
      at[ref.qdd[j]] = 2 * u(rng);
      at[ref.tau[j]] = 5 * u(rng);
    }
    const auto a = ref_models(at), b = our_models(at);
    const std::size_t n = ref.n, nb = ref.base.size();
    std::size_t at_part = 0;
    auto part = [&](const char* what, std::size_t size, double tol) {
      const std::vector<double> x(a.begin() + at_part, a.begin() + at_part + size),
          y(b.begin() + at_part, b.begin() + at_part + size);
      EXPECT_LT(relative_difference(x, y), tol) << robot << " " << what << ", trial " << trial;
      at_part += size;
    };
    part("idm", n, 1e-12);
    part("ccg", n, 1e-12);
    part("inm", n * n, 1e-12);
    part("fgm", 16, 1e-12);
    part("jac", 6 * n, 1e-12);
    part("dim", n * nb, 1e-12);
    part("ddm", n, 1e-12);
  }
}

INSTANTIATE_TEST_SUITE_P(Robots, ModelFromPar,
                         ::testing::Values("planar2r", "stanford_rrp", "rx90", "crane_x7", "crane_x7_reduced"));

}  // namespace
}  // namespace symoro::codegen
