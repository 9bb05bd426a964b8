// The robot library (symoro/robot_abi.h): built from a robot folder by the runtime on first use,
// loaded, and equal bit for bit to the generated headers called inline, on three robots (the
// planar 2R with its effects variant, the RX-90 with its `rigid` variant, the Stanford RRP with a
// prismatic joint); the cache; and the loader's refusals (another ABI, not a robot library, a
// stale folder, a missing compiler), each with its message.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "symoro/codegen/robot_library.hpp"
#include "symoro/planar2r.hpp"
#include "symoro/robot/load_robot.hpp"
#include "symoro/rx90.hpp"
#include "symoro/stanford_rrp.hpp"

namespace fs = std::filesystem;
using symoro::robot::LoadError;
using symoro::robot::ModelHandle;

namespace {

// The build tree's robot cache: ctest's processes share it (builds are safe side by side), so a
// library is built once per build tree, not once per test.
fs::path cache_dir() { return SYMORO_TEST_ROBOT_CACHE; }

// Where the tests copy robot folders to edit them, removed at the end.
fs::path scratch_root() {
  static const fs::path dir = fs::temp_directory_path() / ("symoro-test-robot-library-" + std::to_string(::getpid()));
  return dir;
}
struct RemoveScratch : ::testing::Environment {
  void TearDown() override { fs::remove_all(scratch_root()); }
};
const auto* const remove_scratch = ::testing::AddGlobalTestEnvironment(new RemoveScratch);

symoro::robot::LoadOptions options() {
  symoro::robot::LoadOptions o;
  o.cache_dir = cache_dir();
  return o;
}

template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;

// Every kernel of a loaded model against the generated Model's inline call, at random states.
template <class Model>
void expect_kernels_equal(const ModelHandle& h, unsigned seed) {
  constexpr int n = Model::nq, np = Model::np, ns = Model::ns;
  ASSERT_EQ(h.nq(), n);
  ASSERT_EQ(h.np(), np);
  ASSERT_EQ(h.ns(), ns);
  ASSERT_EQ(h.parent_np(), Model::Parent::np);
  EXPECT_EQ(h.variant(), std::string(Model::variant_name));
  for (int i = 0; i < np; ++i) {
    EXPECT_EQ(std::string(h.parameters()[i].name), Model::parameters[i].name);
    EXPECT_EQ(h.parent_index()[i], Model::parent_index[i]);
  }
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(std::string(h.joints()[i].name), Model::joints[i].name);
    EXPECT_EQ(h.joints()[i].type, Model::joints[i].type);
    EXPECT_EQ(h.joints()[i].upper, Model::joints[i].upper);
  }
  EXPECT_EQ(h.fixed_parameters().size(), Model::fixed_parameters.size());
  EXPECT_EQ(h.gravity()(2), Model::gravity[2]);

  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  auto rnd = [&](auto& m) {
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = u(gen);
  };
  for (int trial = 0; trial < 5; ++trial) {
    Mat<n, 1> q, qd, qdd, tau;
    Mat<np, 1> phi;
    Mat<ns, 1> s;
    rnd(q), rnd(qd), rnd(qdd), rnd(tau), rnd(phi), rnd(s);
    // A positive definite inertia for the forward dynamics: phi from physical-looking standard
    // parameters is not needed for equality; both sides get the same (maybe indefinite) M.
    {
      Mat<n, np> a, b;
      Model::regressor(q, qd, qdd, a);
      h.regressor(q.data(), qd.data(), qdd.data(), b.data());
      EXPECT_EQ(a, b);
    }
    {
      Mat<n, 1> a, b;
      Model::fixed_torque(q, qd, qdd, a);
      h.fixed_torque(q.data(), qd.data(), qdd.data(), b.data());
      EXPECT_EQ(a, b);
      Model::inverse_dynamics(q, qd, qdd, phi, a);
      h.inverse_dynamics(q.data(), qd.data(), qdd.data(), phi.data(), b.data());
      EXPECT_EQ(a, b);
      Model::nonlinear_effects(q, qd, phi, a);
      h.nonlinear_effects(q.data(), qd.data(), phi.data(), b.data());
      EXPECT_EQ(a, b);
      Model::forward_dynamics(q, qd, tau, phi, a);
      h.forward_dynamics(q.data(), qd.data(), tau.data(), phi.data(), b.data());
      EXPECT_TRUE(a == b || (a.hasNaN() && b.hasNaN()));
    }
    {
      Mat<n, n> a, b;
      Model::inertia(q, phi, a);
      h.inertia(q.data(), phi.data(), b.data());
      EXPECT_EQ(a, b);
      auto basis = std::make_unique<typename Model::template InertiaBasis<double>>();
      Model::inertia_basis(q, *basis);
      Mat<n, n> constant;
      std::vector<double> linear(static_cast<std::size_t>(np) * n * n);
      h.inertia_basis(q.data(), constant.data(), linear.data());
      EXPECT_EQ(constant, basis->constant);
      for (int i = 0; i < np; ++i) EXPECT_EQ((Eigen::Map<Mat<n, n>>(linear.data() + i * n * n)), basis->linear[i]);
    }
    {
      typename Model::template InverseDynamicsDerivatives<double> d;
      Model::inverse_dynamics_derivatives(q, qd, qdd, phi, d);
      Mat<n, 1> t;
      Mat<n, n> dq, dqd;
      h.inverse_dynamics_derivatives(q.data(), qd.data(), qdd.data(), phi.data(), t.data(), dq.data(), dqd.data());
      EXPECT_EQ(t, d.tau);
      EXPECT_EQ(dq, d.dq);
      EXPECT_EQ(dqd, d.dqd);
    }
    {
      typename Model::template ForwardDynamicsDerivatives<double> d;
      const bool ok = Model::forward_dynamics_derivatives(q, qd, tau, phi, d);
      Mat<n, 1> a;
      Mat<n, n> dq, dqd, dtau;
      Mat<n, np> dphi;
      double pivot = 0;
      EXPECT_EQ(h.forward_dynamics_derivatives(q.data(), qd.data(), tau.data(), phi.data(), a.data(), dq.data(),
                                               dqd.data(), dtau.data(), dphi.data(), &pivot),
                ok);
      EXPECT_EQ(pivot, d.min_pivot);
      if (ok) {
        EXPECT_EQ(a, d.qdd);
        EXPECT_EQ(dq, d.dq);
        EXPECT_EQ(dqd, d.dqd);
        EXPECT_EQ(dtau, d.dtau);
        EXPECT_EQ(dphi, d.dphi);
      }
    }
    {
      typename Model::template InertiaDerivatives<double> d;
      Model::inertia_derivatives(q, phi, d);
      Mat<n, n> M, M2;
      std::vector<double> dM(n * n * n), dM2(n * n * n), d2M(n * n * n * n);
      h.inertia_derivatives(q.data(), phi.data(), M.data(), dM.data());
      EXPECT_EQ(M, d.M);
      for (int k = 0; k < n; ++k) EXPECT_EQ((Eigen::Map<Mat<n, n>>(dM.data() + k * n * n)), d.dq[k]);
      // The second derivatives against central differences of the first.
      h.inertia_second_derivatives(q.data(), phi.data(), M2.data(), dM2.data(), d2M.data());
      EXPECT_EQ(M2, M);
      EXPECT_EQ(dM2, dM);
      const double e = 1e-6;
      for (int l = 0; l < n; ++l) {
        Mat<n, 1> qp = q, qm = q;
        qp(l) += e;
        qm(l) -= e;
        typename Model::template InertiaDerivatives<double> dp, dm;
        Model::inertia_derivatives(qp, phi, dp);
        Model::inertia_derivatives(qm, phi, dm);
        for (int k = 0; k < n; ++k) {
          const Mat<n, n> fd = (dp.dq[k] - dm.dq[k]) / (2 * e);
          const Eigen::Map<Mat<n, n>> exact(d2M.data() + (k * n + l) * n * n);
          EXPECT_LE((fd - exact).cwiseAbs().maxCoeff(), 1e-6 * (1 + exact.cwiseAbs().maxCoeff()));
        }
      }
    }
    {
      Mat<4, 4> a, b;
      Model::forward_kinematics(q, a);
      h.forward_kinematics(q.data(), b.data());
      EXPECT_EQ(a, b);
      Mat<6, n> ja, jb;
      Model::jacobian(q, ja);
      h.jacobian(q.data(), jb.data());
      EXPECT_EQ(ja, jb);
    }
    {
      Mat<np, 1> a, b;
      Model::base_from_standard(s, a);
      h.base_from_standard(s.data(), b.data());
      EXPECT_EQ(a, b);
      Mat<Model::Parent::np, 1> pa = Model::to_parent(phi), pb;
      h.to_parent(phi.data(), pb.data());
      EXPECT_EQ(pa, pb);
      Mat<np, 1> fa = Model::from_parent(pa), fb;
      h.from_parent(pa.data(), fb.data());
      EXPECT_EQ(fa, fb);
    }
  }
}

fs::path robot_dir(const std::string& name) { return fs::path(SYMORO_ROBOTS_DIR) / name; }

// A copy of a shipped robot folder the test may edit.
fs::path scratch_copy(const std::string& name, const std::string& tag) {
  const fs::path dir = scratch_root() / tag / name;
  fs::remove_all(dir.parent_path());
  fs::create_directories(dir.parent_path());
  fs::copy(robot_dir(name), dir, fs::copy_options::recursive);
  return dir;
}

}  // namespace

TEST(RobotLibrary, Planar2rAndItsEffectsVariantEqualTheInlineHeaders) {
  const auto lib = symoro::robot::load_robot(robot_dir("planar2r"), options());
  EXPECT_EQ(lib->robot(), "planar2r");
  ASSERT_EQ(lib->model_labels(), (std::vector<std::string>{"full", "effects"}));
  expect_kernels_equal<symoro::planar2r::Model>(lib->model("full"), 1);
  const ModelHandle effects = lib->model("effects");
  EXPECT_EQ(effects.ne(), symoro::planar2r::effects::Model::ne);
  EXPECT_EQ(std::string(effects.effect_parameters()[0].name),
            symoro::planar2r::effects::Model::effect_parameters[0].name);
  expect_kernels_equal<symoro::planar2r::effects::Model>(effects, 2);
}

TEST(RobotLibrary, Rx90AndItsRigidVariantEqualTheInlineHeaders) {
  const auto lib = symoro::robot::load_robot(robot_dir("rx90"), options());
  expect_kernels_equal<symoro::rx90::Model>(lib->model("full"), 3);
  expect_kernels_equal<symoro::rx90::rigid::Model>(lib->model("rigid"), 4);
  // "" is robot.yaml's `identified`.
  EXPECT_EQ(lib->model("").variant(), std::string(symoro::rx90::IdentifiedModel::variant_name));
}

TEST(RobotLibrary, StanfordRrpWithItsPrismaticJointEqualsTheInlineHeaders) {
  const auto lib = symoro::robot::load_robot(robot_dir("stanford_rrp"), options());
  const ModelHandle full = lib->model("full");
  EXPECT_EQ(full.joints()[2].type, symoro::JointType::Prismatic);
  expect_kernels_equal<symoro::stanford_rrp::Model>(full, 5);
}

TEST(RobotLibrary, TheCacheIsReusedAndKeyedByTheGeneratedCode) {
  symoro::codegen::RobotLibraryOptions o;
  o.cache_dir = cache_dir();
  const auto first = symoro::codegen::build_robot_library(robot_dir("planar2r"), o);
  const auto again = symoro::codegen::build_robot_library(robot_dir("planar2r"), o);
  EXPECT_FALSE(again.built);
  EXPECT_EQ(first.library, again.library);
  EXPECT_EQ(first.code_digest, again.code_digest);
  // Same library object for the same file.
  EXPECT_EQ(symoro::robot::RobotLibrary::open(first.library).get(),
            symoro::robot::RobotLibrary::open(again.library).get());

  // A change that changes the generated code (a joint limit) is another library.
  const fs::path dir = scratch_copy("planar2r", "limit");
  {
    std::ifstream in(dir / "robot.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find("velocity: 3.0, effort: 40.0");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 13, "velocity: 2.5");
    std::ofstream(dir / "robot.yaml") << text;
  }
  const auto edited = symoro::codegen::build_robot_library(dir, o);
  EXPECT_NE(edited.code_digest, first.code_digest);
  EXPECT_NE(edited.library, first.library);
  const auto lib = symoro::robot::load_robot(dir, options());
  EXPECT_EQ(lib->model("full").joints()[0].velocity, 2.5);
  EXPECT_EQ(symoro::robot::load_robot(robot_dir("planar2r"), options())->model("full").joints()[0].velocity, 3.0);
}

// symoroc build --objects: the library's model objects for a program that links the robot
// statically (symoro::<robot>_identification), the same objects whether the library was just
// built or found in the cache; the library's entry points are not among them (two robots' would
// clash in one program), and a cached library without its objects names the way out.
TEST(RobotLibrary, ItsObjectsAreWhatAProgramLinksStatically) {
  const fs::path scratch = scratch_root() / "objects";
  fs::remove_all(scratch);
  symoro::codegen::RobotLibraryOptions o;
  o.cache_dir = scratch / "cache";
  o.objects = scratch / "fresh" / "kernels.o";
  const auto built = symoro::codegen::build_robot_library(robot_dir("planar2r"), o);
  ASSERT_TRUE(built.built);
  o.objects = scratch / "cached" / "kernels.o";
  ASSERT_FALSE(symoro::codegen::build_robot_library(robot_dir("planar2r"), o).built);
  for (const char* which : {"fresh", "cached"}) {
    const fs::path objects = scratch / which / "kernels.o";
    ASSERT_TRUE(fs::exists(objects)) << which;
    const fs::path listing = scratch / (std::string(which) + ".nm");
    ASSERT_EQ(std::system(("nm -C --defined-only '" + objects.string() + "' > '" + listing.string() + "'").c_str()), 0);
    std::ifstream in(listing);
    const std::string symbols((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (const char* model : {"symoro::planar2r::Model", "symoro::planar2r::effects::Model"}) {
      EXPECT_NE(symbols.find(std::string("symoro::abi_export::model_abi<") + model + ">()"), std::string::npos)
          << which << " " << model;
      EXPECT_NE(symbols.find(std::string("symoro::abi_export::inertia_second_derivatives<") + model + ">"),
                std::string::npos)
          << which << " " << model;
    }
    EXPECT_NE(symbols.find("symoro_planar2r_model_1()"), std::string::npos) << which;
    EXPECT_EQ(symbols.find("symoro_robot"), std::string::npos)
        << which << ": the library's entry is not for static linking";
  }
  for (const auto& e : fs::directory_iterator(built.library.parent_path() / "src"))
    if (e.path().extension() == ".o") fs::remove(e.path());
  try {
    symoro::codegen::build_robot_library(robot_dir("planar2r"), o);
    ADD_FAILURE() << "objects written from a library folder without them";
  } catch (const symoro::codegen::BuildError& e) {
    EXPECT_NE(std::string(e.what()).find("has no model objects (src/*.o): rebuild it with --force"), std::string::npos)
        << e.what();
  }
}

TEST(RobotLibraryRefusals, AStaleFolderNamesTheFileAndBothDigests) {
  const fs::path dir = scratch_copy("planar2r", "stale");
  const auto lib = symoro::robot::load_robot(dir, options());
  std::ofstream(dir / "robot.yaml", std::ios::app) << "# edited after the build\n";
  try {
    lib->check_folder(dir);
    FAIL() << "a stale folder was accepted";
  } catch (const LoadError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find((dir / "robot.yaml").string() + " differs from the robot.yaml the robot library"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("digest "), std::string::npos) << m;
    EXPECT_NE(m.find(", library "), std::string::npos) << m;
  }
  // load_robot builds the edited folder's own library instead.
  EXPECT_NE(symoro::robot::load_robot(dir, options())->path(), lib->path());
}

TEST(RobotLibraryRefusals, AnotherAbiVersionIsRefusedNamingBoth) {
  try {
    symoro::robot::RobotLibrary::open(SYMORO_FAKE_ABI_LIBRARY);
    FAIL() << "a library of ABI version 999 was loaded";
  } catch (const LoadError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("ABI version 999, this symoro reads ABI version " + std::to_string(SYMORO_ROBOT_ABI_VERSION)),
              std::string::npos)
        << m;
  }
}

TEST(RobotLibraryRefusals, AFileThatIsNoRobotLibraryIsRefused) {
  try {
    symoro::robot::RobotLibrary::open(SYMORO_NOT_A_ROBOT_LIBRARY);
    FAIL() << "a library without the entry points was loaded";
  } catch (const LoadError& e) {
    EXPECT_NE(std::string(e.what()).find("not a symoro robot library"), std::string::npos) << e.what();
  }
  fs::create_directories(scratch_root());
  const fs::path text = scratch_root() / "not-elf.so";
  std::ofstream(text) << "not a shared object\n";
  EXPECT_THROW(symoro::robot::RobotLibrary::open(text), LoadError);
}

TEST(RobotLibraryRefusals, AMissingCompilerIsNamed) {
  const fs::path dir = scratch_copy("planar2r", "nocompiler");
  std::ofstream(dir / "robot.yaml", std::ios::app) << "# never built\n";
  ::setenv("SYMORO_CXX", "/nonexistent/bin/c++", 1);
  try {
    symoro::robot::load_robot(dir, options());
    ::unsetenv("SYMORO_CXX");
    FAIL() << "a library was built without a compiler";
  } catch (const LoadError& e) {
    ::unsetenv("SYMORO_CXX");
    const std::string m = e.what();
    EXPECT_NE(m.find("the compiler '/nonexistent/bin/c++' is missing (named by SYMORO_CXX)"), std::string::npos) << m;
  }
}

TEST(RobotLibraryRefusals, AModelTheRobotHasNotIsNamedWithTheOnesItHas) {
  const auto lib = symoro::robot::load_robot(robot_dir("rx90"), options());
  try {
    lib->model("nonesuch");
    FAIL();
  } catch (const LoadError& e) {
    EXPECT_NE(std::string(e.what()).find("robot 'rx90' has no model 'nonesuch' (it has: full, rigid)"),
              std::string::npos)
        << e.what();
  }
}
