// Uses the generated CRANE-X7 model through the installed package: the paper's identified
// 39-parameter model (Appendix A) at posture A. Exits non-zero if the regressor and the
// Newton-Euler torque disagree or the inertia matrix is not positive definite.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <symoro/crane_x7.hpp>

int main() {
  namespace m = symoro::crane_x7::reduced;
  using Vec = Eigen::Matrix<double, m::nq, 1>;

  // Appendix A, final parameters (the paper's MZ7 is this model's MY7: a naming difference).
  Eigen::Matrix<double, m::np, 1> phi;
  phi[m::param::ZZR1] = 0.01184;
  phi[m::param::XXR2] = 0.05882, phi[m::param::ZZR2] = 0.09040, phi[m::param::MX2] = 0.00712,
  phi[m::param::MYR2] = -0.23800;
  phi[m::param::XXR3] = 0.00180, phi[m::param::ZZR3] = 0.00172, phi[m::param::MX3] = 0.00962,
  phi[m::param::MYR3] = 0.00110;
  phi[m::param::XXR4] = 0.00991, phi[m::param::ZZR4] = 0.02530, phi[m::param::MX4] = 0.00366,
  phi[m::param::MYR4] = -0.14297;
  phi[m::param::XXR5] = 0.01560, phi[m::param::ZZR5] = 0.00024, phi[m::param::MX5] = -0.00206,
  phi[m::param::MYR5] = 0.00137;
  phi[m::param::XXR6] = 0.00083, phi[m::param::ZZR6] = -0.00003, phi[m::param::MX6] = 0.00130,
  phi[m::param::MYR6] = -0.00522;
  phi[m::param::XXR7] = 0.00014, phi[m::param::ZZ7] = -0.00003, phi[m::param::MX7] = -0.00034,
  phi[m::param::MY7] = -0.00005;
  const double ia[] = {0.00713, 0.01270, 0.00414, 0.00373, 0.00448, 0.00499};
  for (int i = 0; i < 6; ++i) phi[m::param::IA3 + i] = ia[i];
  const double fv[] = {0.0736, 0.317, 0.0707, 0.247, 0.0287, 0.0459, 0.0331, 0.0313};
  for (int i = 0; i < 8; ++i) phi[m::param::FV1 + i] = fv[i];

  Vec q = Vec::Zero();
  q[3] = -M_PI / 2;  // posture A
  const Vec qd = Vec::Constant(0.2), qdd = Vec::Constant(0.5);

  const Vec tau = m::inverse_dynamics(q, qd, qdd, phi);
  const Vec tau_w = m::regressor(q, qd, qdd) * phi;
  const Vec gravity = m::nonlinear_effects(q, Vec::Zero().eval(), phi);
  const auto M = m::inertia(q, phi);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, m::nq, m::nq>> eig(M);

  std::printf("CRANE-X7, the paper's 39-parameter model at posture A\n");
  std::printf("%-16s %12s %12s\n", "joint", "gravity N m", "tau N m");
  for (int j = 0; j < m::nq; ++j) std::printf("%-16s %12.5f %12.5f\n", m::joints[j].name, gravity[j], tau[j]);
  std::printf("lambda_min(M) = %.6g kg m^2, lambda_max(M) = %.6g kg m^2\n", eig.eigenvalues().minCoeff(),
              eig.eigenvalues().maxCoeff());
  const double mismatch = (tau - tau_w).norm() / tau.norm();
  std::printf("|W phi - tau| / |tau| = %.3g\n", mismatch);
  if (!(mismatch < 1e-12) || !(eig.eigenvalues().minCoeff() > 0)) {
    std::printf("FAILED\n");
    return 1;
  }
  return 0;
}
