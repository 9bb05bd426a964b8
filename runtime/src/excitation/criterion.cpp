#include "symoro/excitation/criterion.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Cholesky>

#include "symoro/mdh.hpp"

namespace symoro::excitation {

namespace {
constexpr double kTwoPi = 6.283185307179586476925286766559;

preprocess::Samples as_samples(const Eigen::MatrixXd& q, const Eigen::MatrixXd& qd, const Eigen::MatrixXd& qdd) {
  preprocess::Samples s;
  s.q = q;
  s.qd = qd;
  s.qdd = qdd;
  s.tau = Eigen::MatrixXd::Zero(q.rows(), q.cols());
  s.time = Eigen::VectorXd::Zero(q.rows());
  s.piece.assign(static_cast<std::size_t>(q.rows()), 0);
  return s;
}
}  // namespace

FourierBasis::FourierBasis(int joints, int harmonics, double period, int samples, Eigen::VectorXd start)
    : n_(joints), L_(harmonics), N_(samples), w_(period > 0 ? kTwoPi / period : 0), start_(std::move(start)) {
  if (n_ < 1 || L_ < 2 || N_ < 4 * L_ || !(period > 0) || start_.size() != n_)
    throw std::invalid_argument(
        "FourierBasis: needs joints >= 1, harmonics >= 2, samples >= 4 harmonics, a positive "
        "period and a start pose of " +
        std::to_string(n_) + " joints");
  bq_.resize(N_, 2 * L_);
  bqd_.resize(N_, 2 * L_);
  bqdd_.resize(N_, 2 * L_);
  for (int k = 0; k < N_; ++k)
    for (int l = 0; l < L_; ++l) {
      const double wl = w_ * (l + 1), s = std::sin(wl * time(k)), c = std::cos(wl * time(k));
      bq_(k, l) = s / wl;
      bq_(k, L_ + l) = (1 - c) / wl;
      bqd_(k, l) = c;
      bqd_(k, L_ + l) = s;
      bqdd_(k, l) = -wl * s;
      bqdd_(k, L_ + l) = wl * c;
    }
}

double FourierBasis::period() const { return kTwoPi / w_; }

void FourierBasis::states(const Eigen::VectorXd& x, Eigen::MatrixXd& q, Eigen::MatrixXd& qd,
                          Eigen::MatrixXd& qdd) const {
  // Column j of X: joint j's coefficients.
  const Eigen::Map<const Eigen::MatrixXd> X(x.data(), 2 * L_, n_);
  q = bq_ * X;
  q.rowwise() += start_.transpose();
  qd = bqd_ * X;
  qdd = bqdd_ * X;
}

trajectory::FourierTrajectory FourierBasis::trajectory(const Eigen::VectorXd& x, const std::string& name) const {
  trajectory::FourierTrajectory t;
  t.name = name;
  t.w = w_;
  t.a.resize(n_, L_);
  t.b.resize(n_, L_);
  t.q0 = start_;
  for (int j = 0; j < n_; ++j)
    for (int l = 0; l < L_; ++l) {
      t.a(j, l) = x(j * 2 * L_ + l);
      t.b(j, l) = x(j * 2 * L_ + L_ + l);
      t.q0(j) += t.b(j, l) / (w_ * (l + 1));
    }
  return t;
}

Eigen::VectorXd FourierBasis::coefficients(const trajectory::FourierTrajectory& t) const {
  if (t.joints() != n_ || t.harmonics() != L_)
    throw std::invalid_argument("FourierBasis::coefficients: " + t.name + " has another size");
  Eigen::VectorXd x(variables());
  for (int j = 0; j < n_; ++j) {
    x.segment(j * 2 * L_, L_) = t.a.row(j).transpose();
    x.segment(j * 2 * L_ + L_, L_) = t.b.row(j).transpose();
  }
  return x;
}

ExcitationCriterion::ExcitationCriterion(const identify::IdentificationModel& model, FourierBasis basis)
    : model_(model), basis_(std::move(basis)), scales_(Eigen::VectorXd::Ones(model.description().np)) {
  if (basis_.joints() != model.description().nq)
    throw std::invalid_argument("ExcitationCriterion: the basis has " + std::to_string(basis_.joints()) +
                                " joints, the model " + std::to_string(model.description().nq));
  if (basis_.samples() * basis_.joints() < model.description().np)
    throw std::invalid_argument("ExcitationCriterion: " + std::to_string(basis_.samples()) + " instants of " +
                                std::to_string(basis_.joints()) + " joints cannot determine " +
                                std::to_string(model.description().np) + " parameters");
}

void ExcitationCriterion::set_parameter_map(const Eigen::MatrixXd& P) {
  if (P.size() > 0 && P.rows() != model_.description().np)
    throw std::invalid_argument("ExcitationCriterion: a parameter map of " + std::to_string(P.rows()) +
                                " rows for a model of " + std::to_string(model_.description().np) + " parameters");
  map_ = P;
  scales_ = Eigen::VectorXd::Ones(parameters());
}

int ExcitationCriterion::parameters() const {
  return map_.size() > 0 ? static_cast<int>(map_.cols()) : model_.description().np;
}

Eigen::MatrixXd ExcitationCriterion::regressor(const Eigen::MatrixXd& q, const Eigen::MatrixXd& qd,
                                               const Eigen::MatrixXd& qdd) const {
  Eigen::MatrixXd W = model_.stack_regression(as_samples(q, qd, qdd)).W;
  if (map_.size() > 0) W = W * map_;
  return W;
}

void ExcitationCriterion::scale_columns_at(const Eigen::VectorXd& x) {
  Eigen::MatrixXd q, qd, qdd;
  basis_.states(x, q, qd, qdd);
  const Eigen::VectorXd norms = regressor(q, qd, qdd).colwise().norm().transpose();
  for (Eigen::Index p = 0; p < norms.size(); ++p) scales_(p) = norms(p) > 0 ? 1 / norms(p) : 1.0;
}

std::optional<double> ExcitationCriterion::value(const Eigen::VectorXd& x, Eigen::VectorXd* gradient) const {
  const int n = basis_.joints(), N = basis_.samples();
  Eigen::MatrixXd q, qd, qdd;
  basis_.states(x, q, qd, qdd);
  const Eigen::MatrixXd W = regressor(q, qd, qdd);
  const Eigen::MatrixXd WS = W * scales_.asDiagonal();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(W.cols(), W.cols());
  A.selfadjointView<Eigen::Lower>().rankUpdate(WS.adjoint(), 1.0 / N);
  const Eigen::LLT<Eigen::MatrixXd> llt(A.selfadjointView<Eigen::Lower>());
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::VectorXd diag = llt.matrixL().toDenseMatrix().diagonal();
  if (!(diag.minCoeff() > 0)) return std::nullopt;
  const double f = -2 * diag.array().log().sum();
  if (!gradient) return f;

  // C = S A^-1 S / N; d f / d state_k = -2 sum_i d (W_k(i, :) (W_k C)(i, :)') / d state_k. With
  // a map, W = W_phi P: the row of W_phi times P C P' W(i, :)'.
  const Eigen::MatrixXd C =
      scales_.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(W.cols(), W.cols())) * scales_.asDiagonal() / N;
  const Eigen::MatrixXd G = map_.size() > 0 ? Eigen::MatrixXd(W * C * map_.transpose()) : Eigen::MatrixXd(W * C);
  Eigen::MatrixXd Hq = Eigen::MatrixXd::Zero(N, n), Hqd = Hq, Hqdd = Hq;
  identify::StateDerivatives d;
  for (int k = 0; k < N; ++k) {
    const Eigen::VectorXd qk = q.row(k).transpose(), qdk = qd.row(k).transpose(), qddk = qdd.row(k).transpose();
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd g = G.row(static_cast<Eigen::Index>(k) * n + i).transpose();
      model_.state_derivatives(qk, qdk, qddk, g, false, d);
      Hq.row(k) += d.dq.row(i);
      Hqd.row(k) += d.dqd.row(i);
      Hqdd.row(k) += d.dqdd.row(i);
    }
  }
  const int B = basis_.block();
  gradient->resize(basis_.variables());
  for (int j = 0; j < n; ++j)
    gradient->segment(j * B, B) = -2 * (basis_.bq().transpose() * Hq.col(j) + basis_.bqd().transpose() * Hqd.col(j) +
                                        basis_.bqdd().transpose() * Hqdd.col(j));
  return f;
}

Eigen::MatrixXd ExcitationCriterion::torque(const Eigen::VectorXd& x, const Eigen::VectorXd& phi,
                                            Eigen::MatrixXd* jacobian) const {
  const int n = basis_.joints(), N = basis_.samples(), B = basis_.block();
  Eigen::MatrixXd q, qd, qdd;
  basis_.states(x, q, qd, qdd);
  Eigen::MatrixXd tau(N, n);
  if (jacobian) jacobian->setZero(static_cast<Eigen::Index>(N) * n, basis_.variables());
  identify::StateDerivatives d;
  for (int k = 0; k < N; ++k) {
    model_.state_derivatives(q.row(k).transpose(), qd.row(k).transpose(), qdd.row(k).transpose(), phi, true, d);
    tau.row(k) = d.tau.transpose();
    if (!jacobian) continue;
    for (int j = 0; j < n; ++j)
      for (int m = 0; m < n; ++m)
        jacobian->block(static_cast<Eigen::Index>(k) * n + j, m * B, 1, B) =
            d.dq(j, m) * basis_.bq().row(k) + d.dqd(j, m) * basis_.bqd().row(k) + d.dqdd(j, m) * basis_.bqdd().row(k);
  }
  return tau;
}

Eigen::MatrixXd ExcitationCriterion::workspace(const Eigen::VectorXd& x, const std::vector<HalfSpace>& spaces,
                                               Eigen::MatrixXd* jacobian) const {
  const int n = basis_.joints(), N = basis_.samples(), B = basis_.block(), H = static_cast<int>(spaces.size());
  Eigen::MatrixXd q, qd, qdd;
  basis_.states(x, q, qd, qdd);
  Eigen::MatrixXd out(N, H);
  if (jacobian) jacobian->setZero(static_cast<Eigen::Index>(N) * H, basis_.variables());
  Eigen::MatrixXd dq;
  for (int k = 0; k < N; ++k) {
    out.row(k) = half_space_values(model_.description().frames, q.row(k).transpose(), spaces, jacobian ? &dq : nullptr)
                     .transpose();
    if (!jacobian) continue;
    for (int h = 0; h < H; ++h)
      for (int m = 0; m < n; ++m)
        jacobian->block(static_cast<Eigen::Index>(k) * H + h, m * B, 1, B) = dq(h, m) * basis_.bq().row(k);
  }
  return out;
}

Eigen::VectorXd half_space_values(const std::vector<FrameInfo>& frames, const Eigen::VectorXd& q,
                                  const std::vector<HalfSpace>& spaces, Eigen::MatrixXd* dq) {
  const int nf = static_cast<int>(frames.size());
  const auto T = mdh_poses(frames, q);
  // The joint variable of each frame (-1 for a fixed one).
  std::vector<int> variable(static_cast<std::size_t>(nf), -1);
  for (int f = 0, k = 0; f < nf; ++f)
    if (frames[static_cast<std::size_t>(f)].sigma != 2) variable[static_cast<std::size_t>(f)] = k++;
  Eigen::VectorXd out(spaces.size());
  if (dq) dq->setZero(static_cast<Eigen::Index>(spaces.size()), q.size());
  for (std::size_t h = 0; h < spaces.size(); ++h) {
    const HalfSpace& s = spaces[h];
    if (s.frame < 1 || s.frame > nf)
      throw std::invalid_argument("half-space " + s.name + ": frame " + std::to_string(s.frame) +
                                  " is not one of the model's 1.." + std::to_string(nf));
    const Eigen::Vector3d p = T[static_cast<std::size_t>(s.frame - 1)].translation();
    out(static_cast<Eigen::Index>(h)) = s.normal.dot(p) - s.offset;
    if (!dq) continue;
    for (int f = s.frame; f != 0; f = frames[static_cast<std::size_t>(f - 1)].ant) {
      const int v = variable[static_cast<std::size_t>(f - 1)];
      if (v < 0) continue;
      const Eigen::Isometry3d& Tf = T[static_cast<std::size_t>(f - 1)];
      const Eigen::Vector3d z = Tf.linear().col(2);
      const Eigen::Vector3d dp =
          frames[static_cast<std::size_t>(f - 1)].sigma == 1 ? z : Eigen::Vector3d(z.cross(p - Tf.translation()));
      (*dq)(static_cast<Eigen::Index>(h), v) = s.normal.dot(dp);
    }
  }
  return out;
}

}  // namespace symoro::excitation
