// A loaded robot model as an IdentificationModel: the generated Model's adapter
// (identification_model-inl.hpp and the templates it calls) written once over a ModelHandle, with
// the same operations in the same order, so that every number equals the compiled model's.
#include "symoro/identify/loaded_model.hpp"

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "symoro/identify/detail/physical_consistency_model.hpp"
#include "symoro/identify/loaded_closed_loop.hpp"
#include "symoro/identify/physical_projection.hpp"

namespace symoro::identify {
namespace {

using robot::ModelHandle;

void check_size(const char* what, Eigen::Index size, int expected) {
  if (size != expected)
    throw std::invalid_argument(std::string("InertiaFunction: ") + what + " has " + std::to_string(size) +
                                " entries, expected " + std::to_string(expected));
}

class LoadedInertiaFunction final : public InertiaFunction {
 public:
  explicit LoadedInertiaFunction(ModelHandle m) : m_(std::move(m)) {}
  int joints() const override { return m_.nq(); }
  int parameters() const override { return m_.np(); }

  void inertia(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M) const override {
    check(q, phi);
    M.resize(m_.nq(), m_.nq());
    m_.inertia(q.data(), phi.data(), M.data());
  }
  void basis(const Eigen::VectorXd& q, Eigen::MatrixXd& constant, std::vector<Eigen::MatrixXd>& linear) const override {
    check_size("q", q.size(), m_.nq());
    const int n = m_.nq();
    constant.resize(n, n);
    std::vector<double> blocks(static_cast<std::size_t>(m_.np()) * n * n);
    m_.inertia_basis(q.data(), constant.data(), blocks.data());
    linear.assign(static_cast<std::size_t>(m_.np()), Eigen::MatrixXd(n, n));
    for (int i = 0; i < m_.np(); ++i)
      linear[static_cast<std::size_t>(i)] = Eigen::Map<const Eigen::MatrixXd>(blocks.data() + i * n * n, n, n);
  }
  void inertia_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                           std::vector<Eigen::MatrixXd>& dM_dq) const override {
    check(q, phi);
    const int n = m_.nq();
    M.resize(n, n);
    std::vector<double> blocks(static_cast<std::size_t>(n) * n * n);
    m_.inertia_derivatives(q.data(), phi.data(), M.data(), blocks.data());
    dM_dq.assign(static_cast<std::size_t>(n), Eigen::MatrixXd(n, n));
    for (int k = 0; k < n; ++k)
      dM_dq[static_cast<std::size_t>(k)] = Eigen::Map<const Eigen::MatrixXd>(blocks.data() + k * n * n, n, n);
  }
  bool inertia_second_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                                  std::vector<Eigen::MatrixXd>& dM_dq,
                                  std::vector<Eigen::MatrixXd>& d2M_dq2) const override {
    check(q, phi);
    const int n = m_.nq();
    M.resize(n, n);
    std::vector<double> first(static_cast<std::size_t>(n) * n * n), second(static_cast<std::size_t>(n) * n * n * n);
    m_.inertia_second_derivatives(q.data(), phi.data(), M.data(), first.data(), second.data());
    dM_dq.assign(static_cast<std::size_t>(n), Eigen::MatrixXd(n, n));
    d2M_dq2.assign(static_cast<std::size_t>(n) * n, Eigen::MatrixXd(n, n));
    for (int k = 0; k < n; ++k)
      dM_dq[static_cast<std::size_t>(k)] = Eigen::Map<const Eigen::MatrixXd>(first.data() + k * n * n, n, n);
    for (int b = 0; b < n * n; ++b)
      d2M_dq2[static_cast<std::size_t>(b)] = Eigen::Map<const Eigen::MatrixXd>(second.data() + b * n * n, n, n);
    return true;
  }

 private:
  void check(const Eigen::VectorXd& q, const Eigen::VectorXd& phi) const {
    check_size("q", q.size(), m_.nq());
    check_size("phi", phi.size(), m_.np());
  }
  ModelHandle m_;
};

// consistency_structure<Model>() (physical_consistency_model.hpp) over handles.
ConsistencyStructure consistency_structure(const ModelHandle& model, const ModelHandle& parent) {
  Eigen::MatrixXd B(parent.np(), parent.ns());
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(parent.ns()), column(parent.np());
  for (int k = 0; k < parent.ns(); ++k) {
    unit(k) = 1;
    parent.base_from_standard(unit.data(), column.data());
    B.col(k) = column;
    unit(k) = 0;
  }
  return identify::consistency_structure(model.standard_parameters(),
                                         model.ne() ? with_effect_block(B, model.ne()) : std::move(B));
}

class LoadedIdentificationModel final : public IdentificationModel {
 public:
  LoadedIdentificationModel(ModelHandle model, ModelHandle full) : m_(std::move(model)), full_(std::move(full)) {
    d_.robot = m_.robot();
    d_.variant = m_.variant();
    d_.nq = m_.nq();
    d_.np = m_.np();
    d_.parameters = m_.parameters();
    d_.joints = m_.joints();
    d_.standard = m_.standard_parameters();
    d_.frames = m_.frames();
    d_.gravity = m_.gravity();
    for (const auto& f : m_.fixed_parameters()) has_fixed_ = has_fixed_ || f.value != 0;
    supports_ = full_.ns() == m_.ns() - m_.ne();
    if (supports_) structure_ = consistency_structure(m_, full_);
  }
  const ModelDescription& description() const override { return d_; }

  // stack_regression<Model> (regression.hpp).
  Regression stack_regression(const preprocess::Samples& s) const override {
    const int n = m_.nq(), p = m_.np();
    Regression r;
    r.joints = n;
    r.samples = static_cast<int>(s.q.rows());
    r.W.resize(static_cast<Eigen::Index>(r.samples) * n, p);
    r.y.resize(static_cast<Eigen::Index>(r.samples) * n);
    Eigen::MatrixXd w(n, p);
    Eigen::VectorXd q(n), qd(n), qdd(n), tau0(n);
    for (int k = 0; k < r.samples; ++k) {
      q = s.q.row(k).transpose();
      qd = s.qd.row(k).transpose();
      qdd = s.qdd.row(k).transpose();
      m_.regressor(q.data(), qd.data(), qdd.data(), w.data());
      m_.fixed_torque(q.data(), qd.data(), qdd.data(), tau0.data());
      r.W.middleRows(static_cast<Eigen::Index>(k) * n, n) = w;
      r.y.segment(static_cast<Eigen::Index>(k) * n, n) = s.tau.row(k).transpose() - tau0;
    }
    return r;
  }
  Eigen::VectorXd base_from_standard(const Eigen::VectorXd& s) const override {
    if (s.size() != m_.ns())
      throw std::invalid_argument("base_from_standard: " + std::to_string(s.size()) + " standard parameters for " +
                                  std::to_string(m_.ns()));
    return m_.base_from_standard(s);
  }
  // open_loop_torque<Model> (validation.hpp).
  Eigen::MatrixXd open_loop_torque(const preprocess::Samples& s, const Eigen::VectorXd& phi) const override {
    check_phi(phi);
    const int n = m_.nq();
    Eigen::MatrixXd tau(s.q.rows(), n);
    Eigen::VectorXd q(n), qd(n), qdd(n), out(n);
    for (Eigen::Index i = 0; i < s.q.rows(); ++i) {
      q = s.q.row(i).transpose();
      qd = s.qd.row(i).transpose();
      qdd = s.qdd.row(i).transpose();
      m_.inverse_dynamics(q.data(), qd.data(), qdd.data(), phi.data(), out.data());
      tau.row(i) = out.transpose();
    }
    return tau;
  }
  void state_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                         const Eigen::VectorXd& phi, bool with_fixed, StateDerivatives& out) const override {
    const int n = m_.nq();
    if (q.size() != n || qd.size() != n || qdd.size() != n)
      throw std::invalid_argument("state_derivatives: a state of " + std::to_string(q.size()) + " joints for " +
                                  std::to_string(n));
    check_phi(phi);
    out.tau.resize(n);
    out.dq.resize(n, n);
    out.dqd.resize(n, n);
    out.dqdd.resize(n, n);
    m_.inverse_dynamics_derivatives(q.data(), qd.data(), qdd.data(), phi.data(), out.tau.data(), out.dq.data(),
                                    out.dqd.data());
    m_.inertia(q.data(), phi.data(), out.dqdd.data());
    if (has_fixed_ && !with_fixed) {  // the fixed parameters' part, affine: subtract it at phi = 0
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m_.np());
      Eigen::VectorXd tau(n);
      Eigen::MatrixXd dq(n, n), dqd(n, n), M(n, n);
      m_.inverse_dynamics_derivatives(q.data(), qd.data(), qdd.data(), zero.data(), tau.data(), dq.data(), dqd.data());
      m_.inertia(q.data(), zero.data(), M.data());
      out.tau -= tau;
      out.dq -= dq;
      out.dqd -= dqd;
      out.dqdd -= M;
    }
  }
  std::unique_ptr<InertiaFunction> inertia_function() const override {
    return std::make_unique<LoadedInertiaFunction>(m_);
  }
  std::unique_ptr<ClosedLoop> closed_loop(const ClosedLoopSetup& setup,
                                          const trajectory::SampledReference& reference) const override {
    return identify::closed_loop(m_, setup, reference);
  }

  bool supports_physical_consistency() const override { return supports_; }
  // physical_check<Model> (physical_projection.hpp).
  ConsistencyResult physical_check(const Eigen::VectorXd& phi) const override { return check(phi, {}); }
  // physical_projection<Model> (physical_projection.hpp).
  PhysicalProjection physical_projection(const Eigen::VectorXd& phi0, const Eigen::MatrixXd& metric, double clearance,
                                         const Eigen::VectorXd& prior_in, double prior_weight) const override {
    const auto t0 = std::chrono::steady_clock::now();
    PhysicalProjection p;
    p.phi = phi0;
    if (!supports_) {
      p.status = unsupported();
      return p;
    }
    ConsistencyOptions options;
    options.prior_regularization = prior_weight;
    if (metric.rows() != m_.np() || metric.cols() != m_.np())
      throw std::invalid_argument("physical_projection: the metric must be np x np");
    const Eigen::VectorXd prior = detail::standard_prior(prior_in, m_.ns(), m_.ne());
    options.held_rows = fixed_parent_rows();
    options.base_metric_root = parent_metric_root(metric);
    options.infeasible_clearance = clearance;
    p.check = identify::consistent_standard_parameters(structure_, consistency_target(phi0), prior, options);
    p.margin = p.check.feasibility;
    if (p.check.ok()) {
      p.consistent = p.feasible = true;
      p.status = "consistent: " + p.check.message;
    } else if (p.check.status == ConsistencyStatus::NoConsistentSet &&
               p.check.phi_consistent.size() == full_.np() + m_.ne()) {
      p.projected = true;
      p.phi = from_target(p.check.phi_consistent);
      p.distance = (options.base_metric_root * (consistency_target(p.phi) - consistency_target(phi0))).norm();
      const ConsistencyResult v = check(p.phi, prior);
      p.feasible = v.ok();
      p.margin = v.feasibility;
      p.status = p.feasible
                     ? fmt::format("projected onto the consistent set (distance {:.4g}); {}", p.distance, v.message)
                     : fmt::format("the projection has no consistent set after all: {}", v.message);
      if (!p.feasible) p.phi = phi0;
    } else {
      p.status = p.check.message;
    }
    p.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return p;
  }
  ConsistencyResult consistent_standard_parameters(const Eigen::VectorXd& phi, const Eigen::VectorXd& prior,
                                                   const ConsistencyOptions& options) const override {
    if (!supports_) throw std::logic_error(unsupported());
    return identify::consistent_standard_parameters(structure_, consistency_target(phi),
                                                    detail::standard_prior(prior, m_.ns(), m_.ne()), options);
  }
  // The full model's base vector, then the effect parameters (physical_consistency_model.hpp).
  Eigen::VectorXd consistency_target(const Eigen::VectorXd& phi) const override {
    if (!supports_) throw std::logic_error(unsupported());
    check_phi(phi);
    Eigen::VectorXd target(full_.np() + m_.ne());
    m_.to_parent(phi.data(), target.data());
    target.tail(m_.ne()) = phi.tail(m_.ne());
    return target;
  }
  Eigen::VectorXd parent_base_from_standard(const Eigen::VectorXd& s) const override {
    if (!supports_) throw std::logic_error(unsupported());
    if (s.size() != m_.ns())
      throw std::invalid_argument("base_from_standard: " + std::to_string(s.size()) + " standard parameters for " +
                                  std::to_string(m_.ns()));
    Eigen::VectorXd target(full_.np() + m_.ne());
    target.head(full_.np()) = full_.base_from_standard(Eigen::VectorXd(s.head(full_.ns())));
    target.tail(m_.ne()) = s.tail(m_.ne());
    return target;
  }

 private:
  std::string unsupported() const {
    return fmt::format(
        "physical consistency is not available for the {} model: its standard vector ({} entries, {} of them "
        "effect parameters) is not its full model's ({})",
        m_.variant(), m_.ns(), m_.ne(), full_.ns());
  }
  // physical_projection.hpp's target_row and from_target over the handles.
  int target_row(int i) const {
    const int parent = m_.parent_index()[static_cast<std::size_t>(i)];
    return parent >= 0 ? parent : full_.np() + i - (m_.np() - m_.ne());
  }
  Eigen::VectorXd from_target(const Eigen::VectorXd& target) const {
    Eigen::VectorXd phi(m_.np());
    m_.from_parent(target.data(), phi.data());
    phi.tail(m_.ne()) = target.tail(m_.ne());
    return phi;
  }
  void check_phi(const Eigen::VectorXd& phi) const {
    if (phi.size() != m_.np())
      throw std::invalid_argument("phi has " + std::to_string(phi.size()) + " entries, the model " +
                                  std::to_string(m_.np()));
  }
  ConsistencyResult check(const Eigen::VectorXd& phi, Eigen::VectorXd prior) const {
    ConsistencyResult r;
    if (!supports_) {
      r.message = "not checked: " + unsupported();
      return r;
    }
    prior = detail::standard_prior(prior, m_.ns(), m_.ne());
    ConsistencyOptions o;
    o.feasibility_only = true;
    return identify::consistent_standard_parameters(structure_, consistency_target(phi), prior, o);
  }
  std::vector<int> fixed_parent_rows() const {
    const int rows = full_.np() + m_.ne();
    std::vector<int> free(static_cast<std::size_t>(rows), 0), held;
    for (int i = 0; i < m_.np(); ++i) free[static_cast<std::size_t>(target_row(i))] = 1;
    for (int i = 0; i < rows; ++i)
      if (!free[static_cast<std::size_t>(i)]) held.push_back(i);
    return held;
  }
  Eigen::MatrixXd parent_metric_root(const Eigen::MatrixXd& metric) const {
    const Eigen::MatrixXd R = metric.llt().matrixU();
    Eigen::MatrixXd Rp = Eigen::MatrixXd::Zero(m_.np(), full_.np() + m_.ne());
    for (int i = 0; i < m_.np(); ++i) Rp.col(target_row(i)) = R.col(i);
    return Rp;
  }

  ModelHandle m_, full_;
  ModelDescription d_;
  bool has_fixed_ = false, supports_ = false;
  ConsistencyStructure structure_;
};

}  // namespace

std::shared_ptr<const IdentificationModel> identification_model(const robot::ModelHandle& model,
                                                                const robot::ModelHandle& full) {
  return std::make_shared<LoadedIdentificationModel>(model, full);
}

}  // namespace symoro::identify
