#include "symoro/payload/payload_identification.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <fmt/format.h>

#include "consistent_payload.hpp"
#include "symoro/identify/hac_covariance.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/study/options.hpp"

namespace symoro::payload {

namespace {

// The stacked payload regression of all logs: rows sample after sample, joint after joint.
struct Stack {
  Eigen::MatrixXd X;        // rows x 10
  Eigen::MatrixXd Z;        // the instruments (reference_instruments), rows x 10; else empty
  Eigen::VectorXd y;        // tau - ID(phi)
  std::vector<int> log_of;  // per sample
  int joints = 0, samples = 0;
};

// The log with its reference motion in place of the measured one (a window's whole file too).
io::Log as_reference(const io::Log& log) {
  io::Log r = log;
  r.q = log.q_ref;
  r.qd = log.qd_ref;
  if (log.file) r.file = std::make_shared<const io::Log>(as_reference(*log.file));
  return r;
}

// The payload regressor of the reference motion on the measured samples' instants.
Eigen::MatrixXd instruments(const io::Log& log, const preprocess::Samples& measured,
                            const identify::IdentificationModel& full, const PayloadLink& link, double interval,
                            const preprocess::Options& po) {
  const std::string name = log.meta.trajectory.empty() ? std::string("a log") : log.meta.trajectory;
  if (!log.has_references())
    throw std::invalid_argument(
        fmt::format("reference instruments: {} has no reference columns (q_ref, qd_ref, qdd_ref)", name));
  // Every row kept: whether an end of the reference moves within the filter's settling time is
  // judged on its own smooth q (no encoder steps), which can differ from the measured motion's
  // judgement; the measured samples choose which instants count.
  preprocess::Options all = po;
  all.trim_settling = false;
  const preprocess::Samples ref = preprocess::preprocess(as_reference(log), interval, all);
  const Eigen::MatrixXd Wr = full.stack_regression(ref).W * link.map;
  const int n = static_cast<int>(measured.q.cols());
  Eigen::MatrixXd Z(measured.time.size() * n, Wr.cols());
  // The reference has no stale rows to leave out: its samples are a superset of the measured
  // ones' instants, matched by time.
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < measured.time.size(); ++i) {
    while (k < ref.time.size() && ref.time(k) < measured.time(i) - 1e-9) ++k;
    if (k == ref.time.size() || std::abs(ref.time(k) - measured.time(i)) > 1e-9)
      throw std::invalid_argument(
          fmt::format("reference instruments: {}'s reference has no sample at {} s, where its measured motion has one",
                      name, measured.time(i)));
    Z.middleRows(i * n, n) = Wr.middleRows(k * n, n);
  }
  return Z;
}

Stack stack(const std::vector<io::Log>& logs, const identify::IdentificationModel& arm, const Eigen::VectorXd& phi,
            const identify::IdentificationModel& full, const PayloadLink& link, const PayloadOptions& o) {
  Stack s;
  s.joints = arm.description().nq;
  std::vector<Eigen::MatrixXd> Xs, Zs;
  std::vector<Eigen::VectorXd> ys;
  // The identification's preprocessing (study/prediction.hpp's, without its raw-rate scoring).
  preprocess::Options po = study::StudyOptions{}.preprocess;
  po.torque_delay = o.torque_delay;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const preprocess::Samples samples = preprocess::preprocess(logs[i], o.interval, po);
    const Eigen::MatrixXd r = samples.tau - arm.open_loop_torque(samples, phi);
    Xs.push_back(full.stack_regression(samples).W * link.map);
    if (o.reference_instruments) Zs.push_back(instruments(logs[i], samples, full, link, o.interval, po));
    Eigen::VectorXd y(r.size());
    for (Eigen::Index k = 0; k < r.rows(); ++k) y.segment(k * s.joints, s.joints) = r.row(k).transpose();
    ys.push_back(std::move(y));
    for (Eigen::Index k = 0; k < r.rows(); ++k) s.log_of.push_back(static_cast<int>(i));
  }
  s.samples = static_cast<int>(s.log_of.size());
  s.X.resize(static_cast<Eigen::Index>(s.samples) * s.joints, kInertialParameters);
  s.y.resize(s.X.rows());
  if (o.reference_instruments) s.Z.resize(s.X.rows(), s.X.cols());
  Eigen::Index at = 0;
  for (std::size_t i = 0; i < Xs.size(); ++i) {
    s.X.middleRows(at, Xs[i].rows()) = Xs[i];
    if (o.reference_instruments) s.Z.middleRows(at, Xs[i].rows()) = Zs[i];
    s.y.segment(at, ys[i].size()) = ys[i];
    at += Xs[i].rows();
  }
  return s;
}

Eigen::VectorXd joint_rms(const Eigen::VectorXd& e, int joints) {
  const Eigen::Map<const Eigen::MatrixXd> E(e.data(), joints, e.size() / joints);
  return (E.rowwise().squaredNorm() / static_cast<double>(E.cols())).cwiseSqrt();
}

// Rows scaled by the joints' weights.
Eigen::MatrixXd weighted(const Eigen::MatrixXd& A, const Eigen::VectorXd& w) {
  Eigen::MatrixXd B = A;
  const int n = static_cast<int>(w.size());
  for (Eigen::Index r = 0; r < B.rows(); ++r) B.row(r) *= w(r % n);
  return B;
}

// The weighted instrumental-variable estimate (Z'W X)^-1 Z'W y (rows weighted as in weighted()).
Eigen::VectorXd instrumented(const Eigen::MatrixXd& Z, const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& w) {
  const Eigen::MatrixXd Zw = weighted(Z, w);
  return (Zw.transpose() * weighted(X, w)).fullPivLu().solve(Zw.transpose() * weighted(y, w));
}

// The reported numbers of a standard vector: mass, CoM (3), inertia about the CoM (6).
Eigen::Matrix<double, 10, 1> reported(const StandardVector& s, const Eigen::Isometry3d& F_in_L) {
  const PayloadInertial p = PayloadInertial::from_standard(s, F_in_L);
  Eigen::Matrix<double, 10, 1> v;
  v << p.mass, p.com, p.inertia(0, 0), p.inertia(1, 1), p.inertia(2, 2), p.inertia(0, 1), p.inertia(0, 2),
      p.inertia(1, 2);
  return v;
}

// Their standard deviations by the delta method (central differences, steps of each
// parameter's own standard deviation / 1000).
Eigen::Matrix<double, 10, 1> reported_std(const StandardVector& s, const Eigen::MatrixXd& C,
                                          const Eigen::Isometry3d& F_in_L) {
  Eigen::Matrix<double, 10, 10> D = Eigen::Matrix<double, 10, 10>::Zero();
  for (int i = 0; i < kInertialParameters; ++i) {
    const double h = std::sqrt(std::max(C(i, i), 0.0)) * 1e-3;
    if (!(h > 0)) continue;
    StandardVector a = s, b = s;
    a(i) += h;
    b(i) -= h;
    D.col(i) = (reported(a, F_in_L) - reported(b, F_in_L)) / (2 * h);
  }
  return (D * C * D.transpose()).diagonal().cwiseMax(0).cwiseSqrt();
}

// The parameter the weakest direction of the scaled regressor leans on most, for the message.
std::string weakest(const Eigen::MatrixXd& Xs, const std::vector<std::string>& names) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Xs, Eigen::ComputeThinV);
  const Eigen::VectorXd v = svd.matrixV().col(Xs.cols() - 1);
  std::string out;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::abs(v(i)) > 0.3)
      out += fmt::format("{}{:+.2f} {}", out.empty() ? "" : " ", v(i), names[static_cast<std::size_t>(i)]);
  return out;
}

}  // namespace

PayloadLink payload_link(const identify::IdentificationModel& model) {
  const auto& d = model.description();
  PayloadLink out;
  for (const auto& p : d.standard)
    if (std::string(p.family) == "M") out.link = std::max(out.link, p.joint);
  if (out.link == 0) throw std::invalid_argument(d.robot + ": the model has no link with a mass parameter");
  const auto& names = payload_standard_names();
  const int ns = static_cast<int>(d.standard.size());
  const Eigen::VectorXd zero = model.base_from_standard(Eigen::VectorXd::Zero(ns));
  out.map = Eigen::MatrixXd::Zero(d.np, kInertialParameters);
  for (int c = 0; c < kInertialParameters; ++c)
    for (int k = 0; k < ns; ++k) {
      const auto& p = d.standard[static_cast<std::size_t>(k)];
      if (p.joint != out.link || std::string(p.family) != names[static_cast<std::size_t>(c)]) continue;
      Eigen::VectorXd unit = Eigen::VectorXd::Zero(ns);
      unit(k) = 1;
      out.map.col(c) = model.base_from_standard(unit) - zero;
    }
  return out;
}

PayloadEstimate identify_payload(const std::vector<io::Log>& logs, const identify::IdentificationModel& arm,
                                 const Eigen::VectorXd& phi, const identify::IdentificationModel& full,
                                 const PayloadOptions& o) {
  return identify_payload(logs, {}, arm, phi, full, o);
}

PayloadEstimate identify_payload(const std::vector<io::Log>& logs, const std::vector<io::Log>& tare,
                                 const identify::IdentificationModel& arm, const Eigen::VectorXd& phi,
                                 const identify::IdentificationModel& full, const PayloadOptions& o) {
  if (logs.empty()) throw std::invalid_argument("identify_payload: no logs");
  if (arm.description().nq != full.description().nq || arm.description().robot != full.description().robot)
    throw std::invalid_argument("identify_payload: the arm's model and the full model are of different robots");
  if (phi.size() != arm.description().np)
    throw std::invalid_argument(
        fmt::format("identify_payload: {} parameters for a model of {}", phi.size(), arm.description().np));
  if (o.mass && !(*o.mass > 0 && std::isfinite(*o.mass)))
    throw std::invalid_argument(fmt::format("identify_payload: a known mass must be positive, not {}", *o.mass));
  const PayloadLink link = payload_link(full);
  const Stack s = stack(logs, arm, phi, full, link, o);
  const Stack t = tare.empty() ? Stack{} : stack(tare, arm, phi, full, link, o);
  const int n = s.joints;
  const bool tared = !tare.empty();

  // The unknowns: the payload's free parameters (all 10, or 9 with a known mass taken to the
  // left side), then with tare logs the arm's error delta along all 10. Rows: the payload's logs,
  // then the tare's (theta's columns 0 there).
  std::vector<int> free;
  std::vector<std::string> names;
  for (int c = 0; c < kInertialParameters; ++c)
    if (!(o.mass && c == 9)) {
      free.push_back(c);
      names.push_back(payload_standard_names()[static_cast<std::size_t>(c)]);
    }
  const int r = static_cast<int>(free.size()), cols = r + (tared ? kInertialParameters : 0);
  if (tared)
    for (int c = 0; c < kInertialParameters; ++c)
      names.push_back(std::string("tare ") + payload_standard_names()[static_cast<std::size_t>(c)]);
  const Eigen::Index rows_s = s.X.rows(), rows = rows_s + t.X.rows();
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(rows, cols), Z;
  for (int i = 0; i < r; ++i) X.col(i).head(rows_s) = s.X.col(free[static_cast<std::size_t>(i)]);
  if (o.reference_instruments) {
    Z = Eigen::MatrixXd::Zero(rows, cols);
    for (int i = 0; i < r; ++i) Z.col(i).head(rows_s) = s.Z.col(free[static_cast<std::size_t>(i)]);
  }
  if (tared) {
    X.block(0, r, rows_s, kInertialParameters) = s.X;
    X.block(rows_s, r, t.X.rows(), kInertialParameters) = t.X;
    if (o.reference_instruments) {
      Z.block(0, r, rows_s, kInertialParameters) = s.Z;
      Z.block(rows_s, r, t.X.rows(), kInertialParameters) = t.Z;
    }
  }
  Eigen::VectorXd y(rows);
  y.head(rows_s) = s.y;
  y.tail(t.y.size()) = t.y;
  if (o.mass) y.head(rows_s) -= s.X.col(9) * *o.mass;
  std::vector<int> log_of = s.log_of;
  for (int l : t.log_of) log_of.push_back(l + static_cast<int>(logs.size()));
  if (X.rows() < 2 * cols) throw std::invalid_argument("identify_payload: too few samples");

  PayloadEstimate out;
  out.link = link.link;
  out.samples = s.samples;
  out.known_mass = o.mass.has_value();
  out.instrumented = o.reference_instruments;
  out.rms_without = joint_rms(s.y, n);

  // Weighted least squares, the weights re-estimated from the residual.
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n), beta;
  for (int it = 0; it <= o.wls_iterations; ++it) {
    const Eigen::MatrixXd Xw = weighted(X, w);
    const Eigen::VectorXd norms = Xw.colwise().norm();
    for (int i = 0; i < cols; ++i)
      if (!(norms(i) > 0))
        throw std::invalid_argument(fmt::format("the logs do not excite the payload's {}: its column is zero",
                                                names[static_cast<std::size_t>(i)]));
    const Eigen::MatrixXd Xs = Xw * norms.cwiseInverse().asDiagonal();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Xs, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    out.condition = sv(0) / sv(cols - 1);
    if (!(out.condition < 1e8))
      throw std::invalid_argument(fmt::format(
          "the logs do not excite the payload's parameters (scaled condition number {:.3g}): the weakest combination "
          "is {}; move the wrist joints more (dynid excite --payload)",
          out.condition, weakest(Xs, names)));
    beta = o.reference_instruments ? instrumented(Z, X, y, w)
                                   : Eigen::VectorXd(norms.cwiseInverse().asDiagonal() * svd.solve(weighted(y, w)));
    if (it == o.wls_iterations) break;
    const Eigen::VectorXd rms = joint_rms(y - X * beta, n);
    for (int j = 0; j < n; ++j) w(j) = rms(j) > 0 ? 1 / rms(j) : 1;
  }
  out.weights = w;

  // The covariance, the residual's autocorrelation counted.
  const Eigen::MatrixXd Xw = weighted(X, w);
  const Eigen::VectorXd ew = weighted(y - X * beta, w);
  out.lags = o.lags >= 0 ? o.lags : identify::residual_lags(ew, log_of, n);
  Eigen::MatrixXd C;
  if (!o.reference_instruments) {
    C = identify::hac_covariance(Xw, ew, log_of, n, out.lags);
  } else {
    // (Z'X)^-1 S_Z (X'Z)^-1, S_Z the long-run covariance of the instruments' scores, which
    // hac_covariance gives between (Z'Z)^-1 factors.
    const Eigen::MatrixXd Zw = weighted(Z, w);
    const Eigen::MatrixXd ZZ = Zw.transpose() * Zw, ZXi = (Zw.transpose() * Xw).inverse();
    C = ZXi * ZZ * identify::hac_covariance(Zw, ew, log_of, n, out.lags) * ZZ * ZXi.transpose();
  }
  out.least_squares.setZero();
  out.covariance.setZero();
  for (int i = 0; i < r; ++i) {
    out.least_squares(free[static_cast<std::size_t>(i)]) = beta(i);
    for (int k = 0; k < r; ++k)
      out.covariance(free[static_cast<std::size_t>(i)], free[static_cast<std::size_t>(k)]) = C(i, k);
  }
  if (o.mass) out.least_squares(9) = *o.mass;
  if (tared) out.tare = beta.tail(kInertialParameters);
  out.tare_samples = t.samples;

  // A body: the estimate, or the nearest one in the covariance's metric.
  out.standard = out.least_squares;
  if (!(consistency_margin(out.least_squares) > 1e-12) || !(out.least_squares(9) > 0)) {
    const ConsistentPayload c = nearest_body(out.least_squares, out.covariance, o.mass.has_value());
    out.standard = c.standard;
    out.distance = c.distance;
    out.projected = true;
    out.status = "the least-squares estimate is no body (" + c.why +
                 "); the nearest body in its covariance's "
                 "metric is reported";
  } else {
    out.status = "the least-squares estimate is a body (positive definite pseudo-inertia)";
  }
  out.margin = consistency_margin(out.standard);

  out.payload = PayloadInertial::from_standard(out.standard, o.flange_in_link);
  const Eigen::Matrix<double, 10, 1> sd = reported_std(out.standard, out.covariance, o.flange_in_link);
  out.mass_std = o.mass ? 0.0 : sd(0);
  out.com_std = sd.segment<3>(1);
  out.inertia_std = sd.segment<6>(4);
  out.rms_with = joint_rms(s.y - s.X * (out.standard + out.tare), n);
  return out;
}

}  // namespace symoro::payload
