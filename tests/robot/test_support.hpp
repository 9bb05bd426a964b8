// Helpers shared by the generated-model tests: relative comparison of Eigen objects, random
// joint states inside the joint limits, physical random standard parameters, and the binding
// of a model's phi to OpenSYMORO parameter names.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <gtest/gtest.h>

#include "newton_euler.hpp"
#include "reference.hpp"

namespace symoro::test {

// Central differences with h = 1e-6 (truncation ~h^2, round-off ~1e-16/h) held to 1e-6 of the
// derivative's magnitude, at kStates random states: the generated-model tests' common settings.
inline constexpr double kFdStep = 1e-6;
inline constexpr double kFdTol = 1e-6;
inline constexpr int kStates = 5;

// |actual - expected| <= rel_tol * scale entry by entry, where scale is the largest magnitude
// in either object: a relative error of the object as a whole, so that entries which cancel to
// nearly 0 are not held to a relative precision no floating-point evaluation has. `columns`
// names the columns in the failure message.
template <class A, class B>
::testing::AssertionResult close(const Eigen::MatrixBase<A>& actual, const Eigen::MatrixBase<B>& expected,
                                 double rel_tol, const std::vector<std::string>& columns = {}) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols())
    return ::testing::AssertionFailure() << "size " << actual.rows() << "x" << actual.cols() << ", expected "
                                         << expected.rows() << "x" << expected.cols();
  const Eigen::MatrixXd a = actual.template cast<double>(), e = expected.template cast<double>();
  if (!a.allFinite()) return ::testing::AssertionFailure() << "non-finite result\n" << a;
  const double scale = std::max(a.cwiseAbs().maxCoeff(), e.cwiseAbs().maxCoeff());
  Eigen::Index r = 0, c = 0;
  const double err = (a - e).cwiseAbs().maxCoeff(&r, &c);
  if (err <= rel_tol * scale) return ::testing::AssertionSuccess();
  std::ostringstream where;
  where << "(" << r << ", " << (c < Eigen::Index(columns.size()) ? columns[c] : std::to_string(c)) << ")";
  return ::testing::AssertionFailure() << "largest difference " << err << " at " << where.str() << ": " << a(r, c)
                                       << " vs " << e(r, c) << "; relative " << err / scale << " > " << rel_tol
                                       << " (scale " << scale << ")";
}

// A fixed-seed generator, so that every run checks the same states.
class Random {
 public:
  explicit Random(unsigned seed) : gen_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen_); }
  // Magnitude in [lo, hi], random sign: nonzero, so sign(qd) is defined.
  double signed_uniform(double lo, double hi) { return (uniform(0, 1) < 0.5 ? -1 : 1) * uniform(lo, hi); }
  template <class V>
  V vector(int n, double lo, double hi) {
    V v(n);
    for (int i = 0; i < n; ++i) v(i) = uniform(lo, hi);
    return v;
  }
  Eigen::Matrix3d rotation() {
    Eigen::Quaterniond u(gauss(), gauss(), gauss(), gauss());
    return u.normalized().toRotationMatrix();
  }

 private:
  double gauss() { return std::normal_distribution<double>()(gen_); }
  std::mt19937 gen_;
};

template <class Model>
using JointVector = Eigen::Matrix<double, Model::nq, 1>;
template <class Model>
using ParameterVector = Eigen::Matrix<double, Model::np, 1>;

template <class Model>
struct State {
  JointVector<Model> q, qd, qdd;
};

// q uniform inside the joint limits; qd and qdd nonzero, of moderate size (rad/s, rad/s^2).
template <class Model>
State<Model> random_state(Random& rng) {
  State<Model> s;
  for (int i = 0; i < Model::nq; ++i) {
    s.q(i) = rng.uniform(Model::joints[i].lower, Model::joints[i].upper);
    s.qd(i) = rng.signed_uniform(0.1, 2.0);
    s.qdd(i) = rng.signed_uniform(0.1, 3.0);
  }
  return s;
}

// phi with every entry of order 1 (no physical meaning; for the checks linear in phi).
template <class Model>
ParameterVector<Model> random_phi(Random& rng) {
  return rng.vector<ParameterVector<Model>>(Model::np, -1.0, 1.0);
}

// A physically consistent rigid link: mass, centre of mass and an inertia about the centre of
// mass that satisfies the triangle inequalities (built from a positive second-moment matrix),
// moved to the frame origin by the parallel-axis theorem; positive rotor inertia and friction.
inline LinkInertia random_physical_link(Random& rng) {
  LinkInertia L;
  L.m = rng.uniform(0.5, 2.0);
  const Eigen::Vector3d c = rng.vector<Eigen::Vector3d>(3, -0.15, 0.15);
  const Eigen::Matrix3d Q = rng.rotation();
  const Eigen::Vector3d second = L.m * rng.vector<Eigen::Vector3d>(3, 0.002, 0.02);
  const Eigen::Matrix3d sigma = Q * second.asDiagonal() * Q.transpose();
  const Eigen::Matrix3d Ic = sigma.trace() * Eigen::Matrix3d::Identity() - sigma;
  L.J = Ic + L.m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  L.ms = L.m * c;
  L.ia = rng.uniform(0.01, 0.05);
  L.fv = rng.uniform(0.05, 0.5);
  L.fs = rng.uniform(0.05, 0.5);
  return L;
}

// The storage of the entry of a link named by an OpenSYMORO family (XX ... FS): one place, or
// two for a product of inertia (both halves of the symmetric tensor).
inline std::vector<double*> link_entry(LinkInertia& L, const std::string& family) {
  static const char* tensor[3][3] = {{"XX", "XY", "XZ"}, {"XY", "YY", "YZ"}, {"XZ", "YZ", "ZZ"}};
  std::vector<double*> out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (family == tensor[r][c]) out.push_back(&L.J(r, c));
  if (family == "MX") out.push_back(&L.ms.x());
  if (family == "MY") out.push_back(&L.ms.y());
  if (family == "MZ") out.push_back(&L.ms.z());
  if (family == "M") out.push_back(&L.m);
  if (family == "IA") out.push_back(&L.ia);
  if (family == "FV") out.push_back(&L.fv);
  if (family == "FS") out.push_back(&L.fs);
  if (out.empty()) throw std::invalid_argument("unknown parameter family '" + family + "'");
  return out;
}

// ---- model-gap effects (robot.yaml `effects`) -------------------------------------------------
// A variant with effects publishes ne and effect_parameters: the last ne entries of phi and of
// s. Their torque terms are written here from the documentation (docs/generated-api.md), not
// taken from the generated code.

template <class Model, class = void>
struct EffectCount : std::integral_constant<int, 0> {};
template <class Model>
struct EffectCount<Model, std::void_t<decltype(Model::ne)>> : std::integral_constant<int, Model::ne> {};
template <class Model>
inline constexpr int effect_count = EffectCount<Model>::value;

inline bool is_effect_family(const std::string& family) {
  return family == "OFF" || family == "FST" || family == "FVA" || family == "HS" || family == "HC" || family == "FC" ||
         family == "FSE";
}

// The term an effect parameter multiplies in its joint's torque, at that joint's q and qd.
inline double effect_term(const std::string& family, int order, double velocity, double q, double qd) {
  if (family == "OFF") return 1.0;
  if (family == "FST") return sign_of(qd) * std::exp(-(qd / velocity) * (qd / velocity));
  if (family == "FVA") return std::abs(qd);
  if (family == "HS") return std::sin(order * q);
  if (family == "HC") return std::cos(order * q);
  if (family == "FC") return std::tanh(qd / velocity);
  if (family == "FSE") return sign_of(qd) * std::exp(-std::abs(qd) / velocity);
  throw std::invalid_argument("unknown effect family '" + family + "'");
}

// The effects' regressor columns (nq x ne): column k holds effect parameter k's term on the row
// of its joint. Empty (nq x 0) for a model without effects.
template <class Model, class Q, class QD>
Eigen::MatrixXd effect_columns(const Q& q, const QD& qd) {
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(Model::nq, effect_count<Model>);
  if constexpr (effect_count < Model >> 0) {
    for (int k = 0; k < Model::ne; ++k) {
      const auto& e = Model::effect_parameters[k];
      const int j = e.joint - 1;
      W(j, k) = effect_term(e.family, e.order, e.velocity, double(q(j)), double(qd(j)));
    }
  }
  return W;
}

// The effects' torque for the effect entries `values` (size ne) of phi or s.
template <class Model, class Q, class QD, class V>
Eigen::VectorXd effect_torque(const Q& q, const QD& qd, const V& values) {
  if constexpr (effect_count<Model> == 0) {
    return Eigen::VectorXd::Zero(Model::nq);
  } else {
    return effect_columns<Model>(q, qd) * Eigen::VectorXd(values.tail(Model::ne));
  }
}

// The number of standard parameters of the robot's .par (Model::ns without the effects).
template <class Model>
inline constexpr int par_standard_count = Model::ns - effect_count<Model>;

// Standard parameters of a model: the vector s of Model::standard_parameters and the same
// values per link, for the Newton-Euler reference (entries s does not list are 0, as in the
// robot's .par).
template <class Model>
struct StandardParameters {
  Eigen::Matrix<double, Model::ns, 1> s;
  std::vector<LinkInertia> links;
};

template <class Model>
std::vector<LinkInertia> links_from_standard(const Eigen::Matrix<double, Model::ns, 1>& s) {
  std::vector<LinkInertia> links(Model::frames.size());
  for (int k = 0; k < par_standard_count<Model>; ++k) {
    const auto& p = Model::standard_parameters[k];
    for (double* slot : link_entry(links.at(p.joint - 1), p.family)) *slot = s(k);
  }
  return links;
}

// Physical random standard parameters: the listed entries of physical random links; the effect
// parameters of a variant with effects (the last ne of s) are drawn in [-0.5, 0.5].
template <class Model>
StandardParameters<Model> random_standard_parameters(Random& rng) {
  std::vector<LinkInertia> drawn;
  for (std::size_t j = 0; j < Model::frames.size(); ++j) drawn.push_back(random_physical_link(rng));
  StandardParameters<Model> out;
  for (int k = 0; k < Model::ns; ++k) {
    const auto& p = Model::standard_parameters[k];
    out.s(k) =
        is_effect_family(p.family) ? rng.uniform(-0.5, 0.5) : *link_entry(drawn.at(p.joint - 1), p.family).front();
  }
  out.links = links_from_standard<Model>(out.s);
  return out;
}

// Random standard parameters that a variant describes exactly: the base parameters it fixes
// take their fixed values. Base parameters are linear in s, so the entries of s that feed a
// fixed parameter are replaced by the minimum-norm solution of "fixed rows of B s = fixed
// values" (B = d phi_full / d s); with fixed values 0 this zeroes them, e.g. the products of
// inertia of a model without them. The other entries stay physical; for the full model
// nothing changes.
template <class Model>
StandardParameters<Model> standard_parameters_of_variant(Random& rng) {
  using Parent = typename Model::Parent;
  StandardParameters<Model> out = random_standard_parameters<Model>(rng);
  const int nfixed = static_cast<int>(Model::fixed_parameters.size());
  if (nfixed == 0) return out;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(Parent::np, Model::ns);  // effect columns stay 0
  for (int k = 0; k < Parent::ns; ++k)
    B.col(k) = Parent::base_from_standard(Eigen::Matrix<double, Parent::ns, 1>::Unit(k));
  Eigen::MatrixXd fixed_rows(nfixed, Model::ns);
  Eigen::VectorXd fixed_values(nfixed);
  for (int f = 0; f < nfixed; ++f) {
    const std::string name = Model::fixed_parameters[f].name;
    int row = 0;
    while (row < Parent::np && name != Parent::parameters[row].name) ++row;
    if (row == Parent::np) throw std::runtime_error("fixed parameter " + name + " is not in the parent");
    fixed_rows.row(f) = B.row(row);
    fixed_values(f) = Model::fixed_parameters[f].value;
  }
  std::vector<int> feeding;
  for (int k = 0; k < Model::ns; ++k)
    if (fixed_rows.col(k).cwiseAbs().maxCoeff() > 0) feeding.push_back(k);
  const Eigen::MatrixXd A = fixed_rows(Eigen::all, feeding);
  const Eigen::VectorXd x = A.completeOrthogonalDecomposition().solve(fixed_values);
  for (std::size_t i = 0; i < feeding.size(); ++i) out.s(feeding[i]) = x(i);
  out.links = links_from_standard<Model>(out.s);
  return out;
}

// The base parameters of the robot's full model by name, from a model's phi (fixed entries of a
// variant filled in by to_parent; effect parameters, which the full model lacks, dropped).
template <class Model>
ParameterValues parent_parameter_values(const ParameterVector<Model>& phi) {
  using Parent = typename Model::Parent;
  const Eigen::Matrix<double, Parent::np, 1> full = Model::to_parent(phi);
  ParameterValues values;
  for (int i = 0; i < Parent::np; ++i) values[Parent::parameters[i].name] = full(i);
  return values;
}

template <class Model>
std::vector<std::string> parameter_names() {
  std::vector<std::string> names;
  for (const auto& p : Model::parameters) names.emplace_back(p.name);
  return names;
}

template <class Model>
Eigen::Vector3d gravity_vector() {
  return {Model::gravity[0], Model::gravity[1], Model::gravity[2]};
}

}  // namespace symoro::test
