// Uses the runtime's stages through the installed package (symoro::identify): a log of the
// CRANE-X7 reduced model written in memory from its generated inverse dynamics (a multi-sine
// motion, no noise), preprocessed, stacked and solved by OLS. Exits non-zero unless the torque
// the estimate predicts on the samples is within 1 % of the true parameters' (what filtering q
// before the nonlinear model costs is well below that).
#include <cmath>
#include <cstdio>

#include <symoro/crane_x7.hpp>
#include <symoro/identify/least_squares.hpp>
#include <symoro/identify/regression.hpp>
#include <symoro/preprocess/preprocess.hpp>

int main() {
  using Model = symoro::crane_x7::reduced::Model;
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  Eigen::Matrix<double, Model::np, 1> phi;
  for (int i = 0; i < Model::np; ++i) phi(i) = 0.01 * (1 + (i % 7));
  symoro::io::Log log;
  log.meta.robot = "crane_x7";
  log.meta.trajectory = "example";
  log.meta.source = "robot";
  log.meta.sample_time = 0.001;
  const int rows = 20000, n = Model::nq;
  log.time.resize(rows);
  log.q.resize(rows, n);
  log.qd.resize(rows, n);
  log.tau.resize(rows, n);
  for (int i = 0; i < rows; ++i) {
    const double t = 0.001 * i;
    Vec q, qd, qdd, tau;
    for (int j = 0; j < n; ++j) {
      const double w1 = 0.7 + 0.13 * j, w2 = 1.9 + 0.07 * j, a = 0.5;
      q(j) = a * (std::sin(w1 * t + j) + 0.5 * std::sin(w2 * t));
      qd(j) = a * (w1 * std::cos(w1 * t + j) + 0.5 * w2 * std::cos(w2 * t));
      qdd(j) = -a * (w1 * w1 * std::sin(w1 * t + j) + 0.5 * w2 * w2 * std::sin(w2 * t));
    }
    Model::inverse_dynamics(q, qd, qdd, phi, tau);
    log.time(i) = t;
    log.q.row(i) = q.transpose();
    log.qd.row(i) = qd.transpose();
    log.tau.row(i) = tau.transpose();
  }
  const symoro::preprocess::Samples s = symoro::preprocess::preprocess(log, 0.010);
  const symoro::identify::Regression r = symoro::identify::stack_regression<Model>(s);
  const symoro::identify::LeastSquaresResult ls = symoro::identify::least_squares(r);
  const double relative = (r.W * (ls.phi - Eigen::VectorXd(phi))).norm() / (r.W * Eigen::VectorXd(phi)).norm();
  std::printf("OLS on %d samples: residual rms %.2e N m, kappa %.1f, predicted torque off by %.2e (relative)\n",
              r.samples, ls.residual_rms, ls.kappa, relative);
  return relative < 1e-2 ? 0 : 1;
}
