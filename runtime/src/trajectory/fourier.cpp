#include "symoro/trajectory/fourier.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace symoro::trajectory {

namespace {
constexpr double kTwoPi = 6.283185307179586476925286766559;
}

double FourierTrajectory::period() const { return w > 0 ? kTwoPi / w : 0.0; }

void FourierTrajectory::evaluate(double t, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const {
  const int n = joints(), L = harmonics();
  q = q0;
  qd = Eigen::VectorXd::Zero(n);
  qdd = Eigen::VectorXd::Zero(n);
  for (int l = 1; l <= L; ++l) {
    const double wl = w * l, s = std::sin(wl * t), c = std::cos(wl * t);
    for (int j = 0; j < n; ++j) {
      const double A = a(j, l - 1), B = b(j, l - 1);
      q(j) += (A * s - B * c) / wl;
      qd(j) += A * c + B * s;
      qdd(j) += wl * (B * c - A * s);
    }
  }
}

Eigen::VectorXd FourierTrajectory::position_bound() const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(joints());
  for (int l = 1; l <= harmonics(); ++l)
    out += (a.col(l - 1).cwiseAbs2() + b.col(l - 1).cwiseAbs2()).cwiseSqrt() / (w * l);
  return out;
}

Eigen::VectorXd FourierTrajectory::velocity_bound() const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(joints());
  for (int l = 1; l <= harmonics(); ++l) out += (a.col(l - 1).cwiseAbs2() + b.col(l - 1).cwiseAbs2()).cwiseSqrt();
  return out;
}

Eigen::VectorXd FourierTrajectory::acceleration_bound() const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(joints());
  for (int l = 1; l <= harmonics(); ++l)
    out += (w * l) * (a.col(l - 1).cwiseAbs2() + b.col(l - 1).cwiseAbs2()).cwiseSqrt();
  return out;
}

void FourierTrajectory::come_to_rest_at(const Eigen::VectorXd& start) {
  const int n = joints(), L = harmonics();
  if (b.rows() != n || b.cols() != L || start.size() != n || L < 2)
    throw std::invalid_argument("FourierTrajectory::come_to_rest_at: sizes do not match (" + std::to_string(n) +
                                " joints, " + std::to_string(L) + " harmonics, at least 2)");
  // sum_l a_l = 0: subtract the mean (the nearest point of that hyperplane).
  for (int j = 0; j < n; ++j) a.row(j).array() -= a.row(j).mean();
  // sum_l l b_l = 0: b -= (l . b) / (l . l) l.
  Eigen::RowVectorXd l = Eigen::RowVectorXd::LinSpaced(L, 1, L);
  for (int j = 0; j < n; ++j) b.row(j) -= (b.row(j).dot(l) / l.squaredNorm()) * l;
  // q(0) = q0 - sum_l b_l / (w l) = start.
  q0 = start;
  for (int j = 0; j < n; ++j)
    for (int k = 1; k <= L; ++k) q0(j) += b(j, k - 1) / (w * k);
}

SampledReference FourierTrajectory::sample(double period_s, int periods) const {
  if (!(period_s > 0) || !(w > 0) || periods < 1)
    throw std::invalid_argument("FourierTrajectory::sample: the period, the pulsation and the count must be positive");
  SampledReference r;
  r.name = name;
  r.period = period_s;
  const int cycles = static_cast<int>(std::lround(periods * period() / period_s)) + 1;
  r.q.resize(joints(), cycles);
  r.qd.resize(joints(), cycles);
  r.qdd.resize(joints(), cycles);
  Eigen::VectorXd q, qd, qdd;
  for (int k = 0; k < cycles; ++k) {
    evaluate(k * period_s, q, qd, qdd);
    r.q.col(k) = q;
    r.qd.col(k) = qd;
    r.qdd.col(k) = qdd;
  }
  return r;
}

}  // namespace symoro::trajectory
