#include "consistent_payload.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <fmt/format.h>

namespace symoro::payload {

namespace {

constexpr int kU = 10;  // u00 u01 u02 u03 u11 u12 u13 u22 u23 u33

// R (theta(U) - theta0), theta(U) the standard parameters of J = U U'.
struct BodyDistance {
  Eigen::Matrix<double, 10, 10> R;
  StandardVector theta0;

  template <class T>
  bool operator()(const T* u, T* residual) const {
    Eigen::Matrix<T, 4, 4> U = Eigen::Matrix<T, 4, 4>::Zero();
    for (int i = 0, k = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) U(i, j) = u[k++];
    const Eigen::Matrix<T, 4, 4> J = U * U.transpose();
    const Eigen::Matrix<T, 3, 3> S = J.template topLeftCorner<3, 3>();
    const Eigen::Matrix<T, 3, 3> I = S.trace() * Eigen::Matrix<T, 3, 3>::Identity() - S;
    Eigen::Matrix<T, 10, 1> theta;
    theta << I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2), J(0, 3), J(1, 3), J(2, 3), J(3, 3);
    const Eigen::Matrix<T, 10, 1> r = R.cast<T>() * (theta - theta0.cast<T>());
    for (int i = 0; i < 10; ++i) residual[i] = r(i);
    return true;
  }
};

// A start inside the cone: the estimate's mass (or a small one), its CoM, and its second moment
// about the CoM with its eigenvalues raised to a small positive floor.
std::array<double, kU> start(const StandardVector& theta0) {
  const Eigen::Matrix4d J = pseudo_inertia(theta0);
  const double m = theta0(9) > 0 ? theta0(9) : std::max(1e-3, std::abs(theta0(9)));
  const Eigen::Vector3d c = theta0(9) > 0 ? Eigen::Vector3d(theta0.segment<3>(6) / m) : Eigen::Vector3d::Zero();
  Eigen::Matrix3d Sc = J.topLeftCorner<3, 3>() - m * c * c.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e((Sc + Sc.transpose()) / 2);
  const double floor = std::max(1e-12, 1e-3 * e.eigenvalues().cwiseAbs().maxCoeff());
  Sc = e.eigenvectors() * e.eigenvalues().cwiseMax(floor).asDiagonal() * e.eigenvectors().transpose();
  // Upper-triangular U with U U' = Sc: the exchange of a lower Cholesky factor of the reversed matrix.
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity().rowwise().reverse();
  const Eigen::Matrix3d L = (P * Sc * P).llt().matrixL();
  const Eigen::Matrix3d Ub = P * L * P;
  Eigen::Matrix4d U = Eigen::Matrix4d::Zero();
  U.topLeftCorner<3, 3>() = Ub;
  U.topRightCorner<3, 1>() = std::sqrt(m) * c;
  U(3, 3) = std::sqrt(m);
  std::array<double, kU> u{};
  for (int i = 0, k = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) u[static_cast<std::size_t>(k++)] = U(i, j);
  return u;
}

}  // namespace

ConsistentPayload nearest_body(const StandardVector& theta0, const Eigen::MatrixXd& covariance, bool known_mass) {
  ConsistentPayload out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> e(pseudo_inertia(theta0));
  out.why = theta0(9) > 0 ? fmt::format("its pseudo-inertia's smallest eigenvalue is {:.3g}", e.eigenvalues()(0))
                          : fmt::format("its mass is {:.4g} kg", theta0(9));

  // The metric's root over the free parameters (a known mass's row is 0: its residual is 0).
  const int r = known_mass ? 9 : 10;
  const Eigen::MatrixXd C = covariance.topLeftCorner(r, r);
  const Eigen::MatrixXd scale = C.diagonal().cwiseMax(1e-300).cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd Cs = scale.inverse() * C * scale.inverse();
  const Eigen::MatrixXd info = Cs.ldlt().solve(Eigen::MatrixXd::Identity(r, r));
  Eigen::MatrixXd Rr = Eigen::LLT<Eigen::MatrixXd>((info + info.transpose()) / 2).matrixU();
  Rr = Rr * scale.inverse();
  BodyDistance* cost = new BodyDistance;
  cost->R.setZero();
  cost->R.topLeftCorner(r, r) = Rr;
  cost->theta0 = theta0;

  std::array<double, kU> u = start(theta0);
  if (known_mass) u[9] = std::sqrt(theta0(9));
  ceres::Problem problem;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BodyDistance, 10, kU>(cost), nullptr, u.data());
  if (known_mass) problem.SetManifold(u.data(), new ceres::SubsetManifold(kU, {9}));
  ceres::Solver::Options options;
  options.max_num_iterations = 500;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.gradient_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  Eigen::Matrix4d U = Eigen::Matrix4d::Zero();
  for (int i = 0, k = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) U(i, j) = u[static_cast<std::size_t>(k++)];
  out.standard = standard_of_pseudo_inertia(U * U.transpose());
  if (known_mass) out.standard(9) = theta0(9);
  out.distance = std::sqrt(2 * summary.final_cost);
  return out;
}

}  // namespace symoro::payload
