// Generic value tests of every robot folder and all its models, compiled once: each robot is
// reached through its robot library (symoroc build, loaded at run time, robot::ModelHandle: the
// seam every runtime command uses), so a new robot folder is tested with no rebuild of this
// program. The references are OpenSYMORO's own model files run by the grammar's interpreter
// (reference.hpp), an independent Newton-Euler (newton_euler.hpp), the effects' hand-written
// terms (test_support.hpp) and central differences for the derivative functions. What only a
// template can check (the generated code in Jets, the output forms into blocks) stays in
// test_robot.cpp and test_robot_derivatives_*.cpp, built for the small shipped robots only
// (tests/CMakeLists.txt). Any robot folder joins with SYMORO_TEST_ROBOT_DIRS (robot_folders.hpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "symoro/grammar/parser.hpp"
#include "robot_folders.hpp"
#include "symoro/robot/load_robot.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using robot::ModelHandle;

// As test_robot.cpp: round-off of two evaluation orders times M's conditioning; central
// differences as test_support.hpp's kFdStep, kFdTol.
constexpr double kRelTol = 1e-9;
constexpr double kSameValue = 1e-12;

std::shared_ptr<const robot::RobotLibrary> library(const std::string& folder) { return test_library(folder); }

struct State {
  VectorXd q, qd, qdd;
};

// Central differences of f (a vector -> any matrix function) around x with step h: column i is
// the derivative along x_i of f's entries in column-major order (jet_support.hpp's, without Jets).
template <class F>
MatrixXd finite_difference_jacobian(const F& f, const VectorXd& x, double h) {
  MatrixXd out;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    VectorXd plus = x, minus = x;
    plus(i) += h;
    minus(i) -= h;
    const MatrixXd d = (MatrixXd(f(plus)) - MatrixXd(f(minus))) / (2 * h);
    if (i == 0) out.resize(d.size(), x.size());
    out.col(i) = Eigen::Map<const VectorXd>(d.data(), d.size());
  }
  return out;
}

std::vector<std::string> names(const std::vector<ParameterInfo>& parameters) {
  std::vector<std::string> out;
  for (const auto& p : parameters) out.emplace_back(p.name);
  return out;
}

// One model of the robot under test, with the handle-based forms of test_support.hpp's helpers.
class RobotValues : public ::testing::TestWithParam<std::string> {
 protected:
  const Reference& ref() const { return reference(GetParam()); }

  // check(model, full, state, phi) at kStates random states with order-1 random phi, for every
  // model of the robot.
  template <class Check>
  void for_models_and_states(const Check& check) {
    const auto lib = library(GetParam());
    const ModelHandle full = lib->model(0);
    for (int i = 0; i < lib->model_count(); ++i) {
      const ModelHandle m = lib->model(i);
      SCOPED_TRACE("model " + m.label());
      for (int k = 0; k < kStates; ++k) {
        SCOPED_TRACE("random state " + std::to_string(k));
        const State s = random_state(m);
        check(m, full, s, static_cast<VectorXd>(rng_.vector<VectorXd>(m.np(), -1.0, 1.0)));
      }
    }
  }
  template <class Check>
  void for_models(const Check& check) {
    const auto lib = library(GetParam());
    for (int i = 0; i < lib->model_count(); ++i) {
      const ModelHandle m = lib->model(i);
      SCOPED_TRACE("model " + m.label());
      check(m, lib->model(0));
    }
  }

  State random_state(const ModelHandle& m) {
    State s{VectorXd(m.nq()), VectorXd(m.nq()), VectorXd(m.nq())};
    for (int i = 0; i < m.nq(); ++i) {
      s.q(i) = rng_.uniform(m.joints()[i].lower, m.joints()[i].upper);
      s.qd(i) = rng_.signed_uniform(0.1, 2.0);
      s.qdd(i) = rng_.signed_uniform(0.1, 3.0);
    }
    return s;
  }
  VectorXd random_torque(const ModelHandle& m) { return rng_.vector<VectorXd>(m.nq(), -5, 5); }
  VectorXd direction(int n) { return direction_rng_.vector<VectorXd>(n, -1, 1); }

  // Standard parameters s of the model's list with the same values per link (Newton-Euler).
  struct Standard {
    VectorXd s;
    std::vector<LinkInertia> links;
  };
  static std::vector<LinkInertia> links_of(const ModelHandle& m, const VectorXd& s) {
    std::vector<LinkInertia> links(m.frames().size());
    for (int k = 0; k < m.ns() - m.ne(); ++k) {
      const auto& p = m.standard_parameters()[k];
      for (double* slot : link_entry(links.at(p.joint - 1), p.family)) *slot = s(k);
    }
    return links;
  }
  // Physical random links; the effect parameters (the last ne of s) in [-0.5, 0.5].
  Standard random_standard(const ModelHandle& m) {
    std::vector<LinkInertia> drawn;
    for (std::size_t j = 0; j < m.frames().size(); ++j) drawn.push_back(random_physical_link(rng_));
    Standard out{VectorXd(m.ns()), {}};
    for (int k = 0; k < m.ns(); ++k) {
      const auto& p = m.standard_parameters()[k];
      out.s(k) =
          is_effect_family(p.family) ? rng_.uniform(-0.5, 0.5) : *link_entry(drawn.at(p.joint - 1), p.family).front();
    }
    out.links = links_of(m, out.s);
    return out;
  }
  // standard_parameters_of_variant (test_support.hpp): the entries of s that feed a fixed base
  // parameter replaced by the minimum-norm solution that gives the fixed values.
  Standard standard_of_variant(const ModelHandle& m, const ModelHandle& full) {
    Standard out = random_standard(m);
    const int nfixed = static_cast<int>(m.fixed_parameters().size());
    if (nfixed == 0) return out;
    MatrixXd B = MatrixXd::Zero(full.np(), m.ns());
    for (int k = 0; k < full.ns(); ++k) B.col(k) = full.base_from_standard(VectorXd(VectorXd::Unit(full.ns(), k)));
    MatrixXd fixed_rows(nfixed, m.ns());
    VectorXd fixed_values(nfixed);
    for (int f = 0; f < nfixed; ++f) {
      const std::string name = m.fixed_parameters()[f].name;
      int row = 0;
      while (row < full.np() && name != full.parameters()[row].name) ++row;
      if (row == full.np()) throw std::runtime_error("fixed parameter " + name + " is not in the full model");
      fixed_rows.row(f) = B.row(row);
      fixed_values(f) = m.fixed_parameters()[f].value;
    }
    std::vector<int> feeding;
    for (int k = 0; k < m.ns(); ++k)
      if (fixed_rows.col(k).cwiseAbs().maxCoeff() > 0) feeding.push_back(k);
    const VectorXd x = MatrixXd(fixed_rows(Eigen::all, feeding)).completeOrthogonalDecomposition().solve(fixed_values);
    for (std::size_t i = 0; i < feeding.size(); ++i) out.s(feeding[i]) = x(i);
    out.links = links_of(m, out.s);
    return out;
  }
  // phi of physical standard parameters: the full model's M is then positive definite.
  VectorXd physical_phi(const ModelHandle& m) { return m.base_from_standard(random_standard(m).s); }

  Random rng_{20261127};
  Random direction_rng_{20261128};
};

// The full model's base parameters by name (a variant's fixed entries filled in by to_parent;
// its effect parameters dropped).
ParameterValues parent_values(const ModelHandle& m, const ModelHandle& full, const VectorXd& phi) {
  VectorXd parent(m.parent_np());
  m.to_parent(phi.data(), parent.data());
  ParameterValues values;
  for (int i = 0; i < full.np(); ++i) values[full.parameters()[i].name] = parent(i);
  return values;
}

// The effects' regressor columns (nq x ne) and torque (test_support.hpp's effect_term).
MatrixXd effect_columns(const ModelHandle& m, const VectorXd& q, const VectorXd& qd) {
  MatrixXd W = MatrixXd::Zero(m.nq(), m.ne());
  for (int k = 0; k < m.ne(); ++k) {
    const auto& e = m.effect_parameters()[k];
    const int j = e.joint - 1;
    W(j, k) = effect_term(e.family, e.order, e.velocity, q(j), qd(j));
  }
  return W;
}
VectorXd effect_torque(const ModelHandle& m, const VectorXd& q, const VectorXd& qd, const VectorXd& values) {
  return effect_columns(m, q, qd) * VectorXd(values.tail(m.ne()));
}

VectorXd nonlinear_effects(const ModelHandle& m, const VectorXd& q, const VectorXd& qd, const VectorXd& phi) {
  VectorXd h(m.nq());
  m.nonlinear_effects(q.data(), qd.data(), phi.data(), h.data());
  return h;
}
VectorXd forward_dynamics(const ModelHandle& m, const VectorXd& q, const VectorXd& qd, const VectorXd& tau,
                          const VectorXd& phi) {
  VectorXd qdd(m.nq());
  m.forward_dynamics(q.data(), qd.data(), tau.data(), phi.data(), qdd.data());
  return qdd;
}
MatrixXd forward_kinematics(const ModelHandle& m, const VectorXd& q) {
  MatrixXd T(4, 4);
  m.forward_kinematics(q.data(), T.data());
  return T;
}
MatrixXd jacobian(const ModelHandle& m, const VectorXd& q) {
  MatrixXd J(6, m.nq());
  m.jacobian(q.data(), J.data());
  return J;
}
VectorXd fixed_torque(const ModelHandle& m, const State& s) {
  VectorXd t(m.nq());
  m.fixed_torque(s.q.data(), s.qd.data(), s.qdd.data(), t.data());
  return t;
}

// ---- a. OpenSYMORO's model files, interpreted -------------------------------------------------

TEST_P(RobotValues, RegressorMatchesDimColumnByName) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd&) {
    const auto columns = names(m.parameters());
    MatrixXd expected = ref().regressor(s.q, s.qd, s.qdd, columns);
    EXPECT_TRUE(expected.rightCols(m.ne()).isZero(0.0)) << "an effect parameter is a column of dim.txt";
    expected.rightCols(m.ne()) = effect_columns(m, s.q, s.qd);
    EXPECT_TRUE(close(m.regressor(s.q, s.qd, s.qdd), expected, kRelTol, columns));
  });
}

TEST_P(RobotValues, InverseDynamicsInertiaAndNonlinearEffectsMatchIdmInmCcg) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle& full, const State& s, const VectorXd& phi) {
    const ParameterValues by_name = parent_values(m, full, phi);
    EXPECT_TRUE(close(m.inverse_dynamics(s.q, s.qd, s.qdd, phi),
                      ref().inverse_dynamics(s.q, s.qd, s.qdd, by_name) + effect_torque(m, s.q, s.qd, phi), kRelTol))
        << "idm";
    EXPECT_TRUE(close(m.inertia(s.q, phi), ref().inertia(s.q, by_name), kRelTol)) << "inm";
    EXPECT_TRUE(close(nonlinear_effects(m, s.q, s.qd, phi),
                      ref().nonlinear_effects(s.q, s.qd, by_name) + effect_torque(m, s.q, s.qd, phi), kRelTol))
        << "ccg";
  });
}

TEST_P(RobotValues, ForwardDynamicsMatchesDdm) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle& full, const State& s, const VectorXd&) {
    const VectorXd phi = physical_phi(m), tau = random_torque(m);
    // The effects' torque acts on the joints like friction: ddm.txt sees tau minus it.
    const VectorXd net = tau - effect_torque(m, s.q, s.qd, phi);
    EXPECT_TRUE(close(forward_dynamics(m, s.q, s.qd, tau, phi),
                      ref().forward_dynamics(s.q, s.qd, net, parent_values(m, full, phi)), kRelTol));
  });
}

TEST_P(RobotValues, ForwardKinematicsAndJacobianMatchFgmAndJac) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd&) {
    EXPECT_TRUE(close(forward_kinematics(m, s.q), ref().forward_kinematics(s.q), kRelTol)) << "fgm";
    EXPECT_TRUE(close(jacobian(m, s.q), ref().jacobian(s.q), kRelTol)) << "jac";
  });
}

// ---- b, c, d. The functions among themselves ------------------------------------------------

TEST_P(RobotValues, RegressorInertiaAndNonlinearEffectsComposeTheInverseDynamics) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd& phi) {
    const VectorXd tau = m.inverse_dynamics(s.q, s.qd, s.qdd, phi);
    EXPECT_TRUE(close(m.regressor(s.q, s.qd, s.qdd) * phi + fixed_torque(m, s), tau, kRelTol)) << "W phi + tau0";
    const MatrixXd A = m.inertia(s.q, phi);
    EXPECT_TRUE(close(A * s.qdd + nonlinear_effects(m, s.q, s.qd, phi), tau, kRelTol)) << "M qdd + h";
    EXPECT_TRUE(close(A, A.transpose(), kRelTol)) << "M symmetric";
    // M is affine in phi through its basis.
    const int n = m.nq();
    MatrixXd constant(n, n), linear(n, n * m.np());
    m.inertia_basis(s.q.data(), constant.data(), linear.data());
    MatrixXd sum = constant;
    for (int i = 0; i < m.np(); ++i) sum += phi(i) * linear.middleCols(i * n, n);
    EXPECT_TRUE(close(A, sum, kRelTol)) << "inertia basis";
  });
}

TEST_P(RobotValues, ForwardDynamicsSolvesInertiaAndInvertsInverseDynamics) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd&) {
    const VectorXd phi = physical_phi(m), tau = random_torque(m);
    const VectorXd qdd = forward_dynamics(m, s.q, s.qd, tau, phi);
    EXPECT_TRUE(
        close(qdd, m.inertia(s.q, phi).partialPivLu().solve(tau - nonlinear_effects(m, s.q, s.qd, phi)), kRelTol));
    EXPECT_TRUE(close(m.inverse_dynamics(s.q, s.qd, qdd, phi), tau, kRelTol));
  });
}

// Along a random direction u of q the Jacobian's linear rows are d p / d q u and its angular rows
// the axial vector of (d R / d q u) R^T, here from central differences of the forward kinematics.
TEST_P(RobotValues, JacobianIsTheDerivativeOfForwardKinematics) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd&) {
    const VectorXd u = direction(m.nq());
    const MatrixXd T = forward_kinematics(m, s.q);
    const MatrixXd dT =
        (forward_kinematics(m, s.q + kFdStep * u) - forward_kinematics(m, s.q - kFdStep * u)) / (2 * kFdStep);
    const Eigen::Matrix3d w = dT.topLeftCorner<3, 3>() * T.topLeftCorner<3, 3>().transpose();
    Eigen::Matrix<double, 6, 1> expected;
    expected << dT(0, 3), dT(1, 3), dT(2, 3), w(2, 1), w(0, 2), w(1, 0);
    EXPECT_TRUE(close(jacobian(m, s.q) * u, expected, kFdTol));
  });
}

// ---- e. Independent Newton-Euler with standard parameters --------------------------------------

TEST_P(RobotValues, NewtonEulerWithStandardParametersGivesInverseDynamicsAndInertia) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle& full, const State& s, const VectorXd&) {
    const Standard standard = standard_of_variant(m, full);
    const VectorXd phi = m.base_from_standard(standard.s);
    // The premise: the variant's fixed parameters have their fixed values.
    VectorXd parent(m.parent_np());
    m.to_parent(phi.data(), parent.data());
    ASSERT_TRUE(close(parent, full.base_from_standard(VectorXd(standard.s.head(full.ns()))), kRelTol));
    const VectorXd ne = newton_euler(m.frames(), m.gravity(), standard.links, s.q, s.qd, s.qdd);
    EXPECT_TRUE(
        close(m.inverse_dynamics(s.q, s.qd, s.qdd, phi), ne + effect_torque(m, s.q, s.qd, standard.s), kRelTol));
    // Column k of M: the torque at rest without gravity for qdd = e_k.
    MatrixXd expected(m.nq(), m.nq());
    for (int k = 0; k < m.nq(); ++k)
      expected.col(k) = newton_euler(m.frames(), Eigen::Vector3d::Zero(), standard.links, s.q, VectorXd::Zero(m.nq()),
                                     VectorXd(VectorXd::Unit(m.nq(), k)));
    const MatrixXd A = m.inertia(s.q, phi);
    EXPECT_TRUE(close(A, expected, kRelTol));
    if (m.variant().empty()) EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatrixXd>(A).eigenvalues().minCoeff(), 0.0);
  });
}

// ---- f. The derivative functions -----------------------------------------------------------------

TEST_P(RobotValues, InverseDynamicsDerivativesAreTheFiniteDifferences) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd& phi) {
    const int n = m.nq();
    VectorXd tau(n);
    MatrixXd dq(n, n), dqd(n, n);
    m.inverse_dynamics_derivatives(s.q.data(), s.qd.data(), s.qdd.data(), phi.data(), tau.data(), dq.data(),
                                   dqd.data());
    EXPECT_TRUE(close(tau, m.inverse_dynamics(s.q, s.qd, s.qdd, phi), kSameValue)) << "tau";
    EXPECT_TRUE(close(dq,
                      finite_difference_jacobian(
                          [&](const VectorXd& x) { return m.inverse_dynamics(x, s.qd, s.qdd, phi); }, s.q, kFdStep),
                      kFdTol))
        << "d tau / d q";
    EXPECT_TRUE(close(dqd,
                      finite_difference_jacobian(
                          [&](const VectorXd& x) { return m.inverse_dynamics(s.q, x, s.qdd, phi); }, s.qd, kFdStep),
                      kFdTol))
        << "d tau / d qd";
  });
}

TEST_P(RobotValues, ForwardDynamicsDerivativesAreTheFiniteDifferencesAndRefuseAnIndefiniteInertia) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd&) {
    const int n = m.nq(), np = m.np();
    const VectorXd phi = physical_phi(m), tau = random_torque(m);
    VectorXd qdd(n);
    MatrixXd dq(n, n), dqd(n, n), dtau(n, n), dphi(n, np);
    double pivot = 0;
    ASSERT_TRUE(m.forward_dynamics_derivatives(s.q.data(), s.qd.data(), tau.data(), phi.data(), qdd.data(), dq.data(),
                                               dqd.data(), dtau.data(), dphi.data(), &pivot));
    EXPECT_GT(pivot, 0);
    EXPECT_TRUE(close(qdd, forward_dynamics(m, s.q, s.qd, tau, phi), kRelTol)) << "qdd";
    const auto fd = [&](const auto& f, const VectorXd& x) { return finite_difference_jacobian(f, x, kFdStep); };
    EXPECT_TRUE(close(dq, fd([&](const VectorXd& x) { return forward_dynamics(m, x, s.qd, tau, phi); }, s.q), kFdTol))
        << "d q";
    EXPECT_TRUE(close(dqd, fd([&](const VectorXd& x) { return forward_dynamics(m, s.q, x, tau, phi); }, s.qd), kFdTol))
        << "d qd";
    EXPECT_TRUE(close(dphi, fd([&](const VectorXd& x) { return forward_dynamics(m, s.q, s.qd, tau, x); }, phi), kFdTol))
        << "d phi";
    const MatrixXd Minv = m.inertia(s.q, phi).inverse();
    EXPECT_TRUE(close(dtau, Minv, 1e-10)) << "M^-1";
    EXPECT_TRUE(close(dphi, -Minv * m.regressor(s.q, s.qd, qdd), 1e-10)) << "-M^-1 W";
    // M(q; -phi) is not positive definite where M(q; phi) is (but for the constant part): refused.
    const VectorXd negative = -phi;
    const double smallest = Eigen::SelfAdjointEigenSolver<MatrixXd>(m.inertia(s.q, negative)).eigenvalues().minCoeff();
    const bool ok = m.forward_dynamics_derivatives(s.q.data(), s.qd.data(), tau.data(), negative.data(), qdd.data(),
                                                   dq.data(), dqd.data(), dtau.data(), dphi.data(), &pivot);
    EXPECT_EQ(ok, smallest > 0) << "smallest eigenvalue " << smallest << ", smallest pivot " << pivot;
  });
}

// d M / d q_k (inertia_derivatives) and d2 M / d q_k d q_l (inertia_second_derivatives, Jets in
// the library) against central differences of inertia() and of inertia_derivatives().
TEST_P(RobotValues, InertiaFirstAndSecondDerivativesAreTheFiniteDifferences) {
  for_models_and_states([&](const ModelHandle& m, const ModelHandle&, const State& s, const VectorXd& phi) {
    const int n = m.nq(), nn = n * n;
    MatrixXd M(n, n), dM(n, nn), M2(n, n), dM2(n, nn), d2M(n, nn * n);
    m.inertia_derivatives(s.q.data(), phi.data(), M.data(), dM.data());
    EXPECT_TRUE(close(M, m.inertia(s.q, phi), kSameValue)) << "M";
    const MatrixXd first =
        finite_difference_jacobian([&](const VectorXd& x) { return m.inertia(x, phi); }, s.q, kFdStep);
    EXPECT_TRUE(close(Eigen::Map<const MatrixXd>(dM.data(), nn, n), first, kFdTol)) << "d M / d q";
    m.inertia_second_derivatives(s.q.data(), phi.data(), M2.data(), dM2.data(), d2M.data());
    EXPECT_EQ(M2, M);
    EXPECT_TRUE(close(dM2, dM, kSameValue)) << "d M / d q of the second derivatives";
    const MatrixXd second = finite_difference_jacobian(
        [&](const VectorXd& x) {
          MatrixXd e(n, n), de(n, nn);
          m.inertia_derivatives(x.data(), phi.data(), e.data(), de.data());
          return de;
        },
        s.q, kFdStep);
    // Block (k n + l) of d2M is d2 M / d q_k d q_l; column l of `second`, rows k nn.., that of d M / d q_k.
    for (int k = 0; k < n; ++k)
      for (int l = 0; l < n; ++l) {
        const MatrixXd got = Eigen::Map<const MatrixXd>(d2M.data() + (k * n + l) * nn, n, n);
        const MatrixXd want = Eigen::Map<const MatrixXd>(second.col(l).data() + k * nn, n, n);
        EXPECT_TRUE(close(got, want, kFdTol)) << "d2 M / d q_" << k + 1 << " d q_" << l + 1;
      }
  });
}

// ---- g. Metadata -------------------------------------------------------------------------------

TEST_P(RobotValues, ParameterMetadataIsWellFormed) {
  static const std::set<std::string> families = {"XX", "XY", "XZ", "YY",  "YZ",  "ZZ",  "MX", "MY", "MZ", "M",
                                                 "IA", "FV", "FS", "OFF", "FST", "FVA", "HS", "HC", "FC", "FSE"};
  for_models([&](const ModelHandle& m, const ModelHandle&) {
    std::set<std::string> seen;
    const int np = m.np(), ne = m.ne();
    ASSERT_EQ(static_cast<int>(m.parameters().size()), np);
    for (int i = 0; i < np; ++i) {
      const auto& p = m.parameters()[i];
      SCOPED_TRACE(p.name);
      EXPECT_TRUE(seen.insert(p.name).second) << "duplicate parameter name";
      EXPECT_NE(std::string(p.unit), "");
      EXPECT_TRUE(families.count(p.family)) << p.family;
      EXPECT_GE(p.joint, 1);
      EXPECT_LE(p.joint, static_cast<int>(m.frames().size()));
      // Effect parameters are the last ne, in the order of effect_parameters, and nothing else is.
      EXPECT_EQ(is_effect_family(p.family), i >= np - ne);
    }
    for (int k = 0; k < ne; ++k) {
      const auto& p = m.parameters()[np - ne + k];
      const auto& e = m.effect_parameters()[k];
      SCOPED_TRACE(e.name);
      EXPECT_EQ(std::string(p.name), e.name);
      EXPECT_EQ(std::string(p.family), e.family);
      EXPECT_EQ(p.joint, e.joint);
      EXPECT_LE(e.joint, m.nq());
      EXPECT_EQ(m.parent_index()[np - ne + k], -1);
      EXPECT_EQ(std::string(m.standard_parameters()[m.ns() - ne + k].name), e.name);
      const std::string family = e.family;
      EXPECT_EQ(e.order >= 1, family == "HS" || family == "HC");
      EXPECT_EQ(e.velocity > 0, family == "FST" || family == "FC" || family == "FSE");
    }
  });
}

// The full model's parameters are exactly the columns of dim.txt and the parameter symbols of its
// tables; a variant's parameters and fixed parameters partition the full model's. to_parent fills
// the fixed values in and from_parent selects: a round trip is the identity but for the effect
// parameters (0), and each parameter keeps its name.
TEST_P(RobotValues, ParametersAreTheBaseParametersOfTheFilesAndMapToTheParent) {
  for_models([&](const ModelHandle& m, const ModelHandle& full) {
    const auto mine_list = names(m.parameters());
    const std::set<std::string> mine(mine_list.begin(), mine_list.end());
    const int ne = m.ne();
    if (m.variant().empty()) {
      const auto columns = ref().regressor_columns();
      const auto& symbols = ref().parameter_symbols();
      EXPECT_EQ(mine, std::set<std::string>(columns.begin(), columns.end()));
      EXPECT_EQ(mine, std::set<std::string>(symbols.begin(), symbols.end()));
      EXPECT_EQ(m.fixed_parameters().size(), 0u);
    } else {
      EXPECT_EQ(m.np() - ne + static_cast<int>(m.fixed_parameters().size()), full.np());
      std::set<std::string> all(mine_list.begin(), mine_list.end() - ne);
      for (const auto& f : m.fixed_parameters()) EXPECT_TRUE(all.insert(f.name).second) << f.name;
      const auto parent = names(full.parameters());
      EXPECT_EQ(all, std::set<std::string>(parent.begin(), parent.end()));
    }
    const VectorXd phi = rng_.vector<VectorXd>(m.np(), -1.0, 1.0);
    VectorXd parent(m.parent_np()), back(m.np());
    m.to_parent(phi.data(), parent.data());
    m.from_parent(parent.data(), back.data());
    VectorXd expected = phi;
    expected.tail(ne).setZero();
    EXPECT_EQ(back, expected);
    const ParameterValues by_name = parent_values(m, full, phi);
    for (int i = 0; i < m.np() - ne; ++i) EXPECT_EQ(by_name.at(m.parameters()[i].name), phi(i));
    for (int i = m.np() - ne; i < m.np(); ++i) EXPECT_EQ(by_name.count(m.parameters()[i].name), 0u);
    for (const auto& f : m.fixed_parameters()) EXPECT_EQ(by_name.at(f.name), f.value) << f.name;
  });
}

// The joints follow the geometry table's movable frames; the frames are the table evaluated with
// robot.yaml's constants; gravity and the standard parameters come from the robot's .par (G, then
// the symbolic entries link by link, family by family; a variant may drop some, keeping the order).
TEST_P(RobotValues, JointsFramesGravityAndStandardParametersFollowTheFiles) {
  const grammar::Table& table = ref().geometry();
  const grammar::ParFile par = grammar::read_par_file(par_file_path(GetParam()));
  const auto entry = [&](const std::string& name) -> const grammar::ParEntry& {
    for (const auto& e : par.entries)
      if (e.name == name) return e;
    throw std::runtime_error(par.path + ": no entry " + name);
  };
  for_models([&](const ModelHandle& m, const ModelHandle&) {
    ASSERT_EQ(m.nq(), ref().nq());
    int k = 0;
    for (const auto& f : m.frames()) {
      if (f.sigma == 2) continue;
      const auto& joint = m.joints()[k++];
      SCOPED_TRACE(joint.name);
      EXPECT_EQ(static_cast<int>(joint.type), f.sigma);
      EXPECT_TRUE(std::isfinite(joint.lower) && std::isfinite(joint.upper));
      EXPECT_LT(joint.lower, joint.upper);
      EXPECT_LE(joint.audit_lower, joint.audit_upper);
      EXPECT_GT(joint.velocity, 0.0);
      EXPECT_GT(joint.effort, 0.0);
    }
    EXPECT_EQ(k, m.nq());

    ASSERT_EQ(m.frames().size(), table.rows.size());
    const std::vector<std::string> columns = {"ant", "sigma", "mu", "gamma", "b", "alpha", "d", "theta", "r"};
    for (std::size_t j = 0; j < table.rows.size(); ++j) {
      const FrameInfo& f = m.frames()[j];
      const Eigen::Matrix<double, 9, 1> generated(f.ant, f.sigma, f.mu, f.gamma, f.b, f.alpha, f.d, f.theta, f.r);
      Eigen::Matrix<double, 9, 1> expected;
      for (int c = 0; c < 9; ++c) {
        const auto at = std::find(table.columns.begin(), table.columns.end(), columns[c]);
        ASSERT_NE(at, table.columns.end()) << columns[c];
        expected(c) = ref().constant_value(table.rows[j].cells[at - table.columns.begin()]);
      }
      EXPECT_TRUE(close(generated, expected, 1e-15, columns)) << "frame " << j + 1;
    }

    const auto& G = entry("G").values;
    ASSERT_EQ(G.size(), 3u);
    const Eigen::Vector3d g(ref().constant_value(G[0]), ref().constant_value(G[1]), ref().constant_value(G[2]));
    EXPECT_TRUE(close(m.gravity(), g, 1e-15));
    std::vector<std::string> expected;
    const char* families[] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FV", "FS"};
    for (std::size_t j = 0; j < m.frames().size(); ++j)
      for (const char* family : families) {
        const grammar::Expr& e = entry(family).values.at(j);
        if (e.kind == grammar::Expr::Kind::Symbol)
          expected.push_back(e.name + " " + family + " " + std::to_string(j + 1));
      }
    std::vector<std::string> listed;
    for (int i = 0; i < m.ns() - m.ne(); ++i) {
      const auto& p = m.standard_parameters()[i];
      listed.push_back(std::string(p.name) + " " + p.family + " " + std::to_string(p.joint));
    }
    if (m.variant().empty()) {
      EXPECT_EQ(listed, expected);
    } else {
      auto from = expected.begin();
      for (const auto& name : listed) {
        from = std::find(from, expected.end(), name);
        EXPECT_NE(from, expected.end()) << name << " is not in the .par, or out of order";
      }
    }
  });
}

// Param: a robot folder (robot_folders.hpp).
INSTANTIATE_TEST_SUITE_P(Robots, RobotValues, ::testing::ValuesIn(test_robot_folders()), folder_test_name);

}  // namespace
}  // namespace symoro::test
