#include "symoro/robot/model_handle.hpp"

#include <stdexcept>

#include "symoro/robot/robot_library.hpp"

namespace symoro::robot {

namespace {

void check_size(const char* what, Eigen::Index got, int want) {
  if (got != want)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(got) + " entries, the model " +
                                std::to_string(want));
}

const char* text(const char* s) { return s ? s : ""; }

}  // namespace

ModelHandle::ModelHandle(std::shared_ptr<const RobotLibrary> library, const symoro_abi_model* model)
    : ModelHandle(library->robot(), model) {
  library_ = std::move(library);
}

ModelHandle::ModelHandle(std::string robot, const symoro_abi_model* model)
    : m_(model), robot_(std::move(robot)), variant_(text(model->variant)), description_(text(model->description)) {
  for (int i = 0; i < m_->np; ++i) {
    const auto& p = m_->parameters[i];
    parameters_.push_back({p.name, p.family, p.joint, p.unit});
    parent_index_.push_back(m_->parent_index[i]);
  }
  for (int i = 0; i < m_->ns; ++i)
    standard_.push_back({m_->standard[i].name, m_->standard[i].family, m_->standard[i].joint});
  for (int i = 0; i < m_->ne; ++i) {
    const auto& e = m_->effects[i];
    effects_.push_back({e.name, e.family, e.joint, e.order, e.velocity});
  }
  for (int i = 0; i < m_->n_fixed; ++i) fixed_.push_back({m_->fixed[i].name, m_->fixed[i].value});
  for (int i = 0; i < m_->nq; ++i) {
    const auto& j = m_->joints[i];
    joints_.push_back({j.name, j.type == 1 ? JointType::Prismatic : JointType::Revolute, j.lower, j.upper, j.velocity,
                       j.effort, j.audit_lower, j.audit_upper});
  }
  for (int i = 0; i < m_->nf; ++i) {
    const auto& f = m_->frames[i];
    frames_.push_back({f.ant, f.sigma, f.mu, f.gamma, f.b, f.alpha, f.d, f.theta, f.r});
  }
}

Eigen::MatrixXd ModelHandle::regressor(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                       const Eigen::VectorXd& qdd) const {
  check_size("q", q.size(), nq());
  check_size("qd", qd.size(), nq());
  check_size("qdd", qdd.size(), nq());
  Eigen::MatrixXd W(nq(), np());
  regressor(q.data(), qd.data(), qdd.data(), W.data());
  return W;
}

Eigen::VectorXd ModelHandle::inverse_dynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                              const Eigen::VectorXd& qdd, const Eigen::VectorXd& phi) const {
  check_size("q", q.size(), nq());
  check_size("qd", qd.size(), nq());
  check_size("qdd", qdd.size(), nq());
  check_size("phi", phi.size(), np());
  Eigen::VectorXd tau(nq());
  inverse_dynamics(q.data(), qd.data(), qdd.data(), phi.data(), tau.data());
  return tau;
}

Eigen::MatrixXd ModelHandle::inertia(const Eigen::VectorXd& q, const Eigen::VectorXd& phi) const {
  check_size("q", q.size(), nq());
  check_size("phi", phi.size(), np());
  Eigen::MatrixXd M(nq(), nq());
  inertia(q.data(), phi.data(), M.data());
  return M;
}

Eigen::VectorXd ModelHandle::base_from_standard(const Eigen::VectorXd& s) const {
  check_size("s", s.size(), ns());
  Eigen::VectorXd phi(np());
  base_from_standard(s.data(), phi.data());
  return phi;
}

}  // namespace symoro::robot
