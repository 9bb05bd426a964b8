// One model of a loaded robot library (symoro/robot_abi.h): its description in the runtime's
// types, and its generated functions called through the library's function pointers over the
// caller's arrays (column-major, outputs caller-owned). What code compiled once for every robot
// uses of a robot model; a handle keeps its library loaded.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/model_info.hpp"
#include "symoro/robot_abi.h"

namespace symoro::robot {

class RobotLibrary;

class ModelHandle {
 public:
  // A model of a loaded library, which the handle keeps loaded.
  ModelHandle(std::shared_ptr<const RobotLibrary> library, const symoro_abi_model* model);
  // A model linked into the program (compiled_model.hpp): its table has static storage.
  ModelHandle(std::string robot, const symoro_abi_model* model);

  const std::string& robot() const { return robot_; }
  const std::string& variant() const { return variant_; }  // "" for the full model
  std::string label() const { return variant_.empty() ? "full" : variant_; }
  const std::string& description() const { return description_; }
  int nq() const { return m_->nq; }
  int np() const { return m_->np; }
  int ns() const { return m_->ns; }
  int nf() const { return m_->nf; }
  int ne() const { return m_->ne; }
  int parent_np() const { return m_->parent_np; }
  const std::vector<ParameterInfo>& parameters() const { return parameters_; }
  const std::vector<StandardParameterInfo>& standard_parameters() const { return standard_; }
  const std::vector<EffectParameterInfo>& effect_parameters() const { return effects_; }
  const std::vector<FixedParameter>& fixed_parameters() const { return fixed_; }
  const std::vector<int>& parent_index() const { return parent_index_; }
  const std::vector<JointInfo>& joints() const { return joints_; }
  const std::vector<FrameInfo>& frames() const { return frames_; }
  Eigen::Vector3d gravity() const { return {m_->gravity[0], m_->gravity[1], m_->gravity[2]}; }
  const symoro_abi_model& abi() const { return *m_; }

  // The generated functions; sizes as in symoro/robot_abi.h. One indirect call each.
  void regressor(const double* q, const double* qd, const double* qdd, double* W) const {
    m_->regressor(q, qd, qdd, W);
  }
  void fixed_torque(const double* q, const double* qd, const double* qdd, double* tau) const {
    m_->fixed_torque(q, qd, qdd, tau);
  }
  void inverse_dynamics(const double* q, const double* qd, const double* qdd, const double* phi, double* tau) const {
    m_->inverse_dynamics(q, qd, qdd, phi, tau);
  }
  void inertia(const double* q, const double* phi, double* M) const { m_->inertia(q, phi, M); }
  void inertia_basis(const double* q, double* constant, double* linear) const {
    m_->inertia_basis(q, constant, linear);
  }
  void nonlinear_effects(const double* q, const double* qd, const double* phi, double* h) const {
    m_->nonlinear_effects(q, qd, phi, h);
  }
  void forward_dynamics(const double* q, const double* qd, const double* tau, const double* phi, double* qdd) const {
    m_->forward_dynamics(q, qd, tau, phi, qdd);
  }
  void inverse_dynamics_derivatives(const double* q, const double* qd, const double* qdd, const double* phi,
                                    double* tau, double* dq, double* dqd) const {
    m_->inverse_dynamics_derivatives(q, qd, qdd, phi, tau, dq, dqd);
  }
  bool forward_dynamics_derivatives(const double* q, const double* qd, const double* tau, const double* phi,
                                    double* qdd, double* dq, double* dqd, double* dtau, double* dphi,
                                    double* min_pivot) const {
    return m_->forward_dynamics_derivatives(q, qd, tau, phi, qdd, dq, dqd, dtau, dphi, min_pivot) != 0;
  }
  void inertia_derivatives(const double* q, const double* phi, double* M, double* dM) const {
    m_->inertia_derivatives(q, phi, M, dM);
  }
  void inertia_second_derivatives(const double* q, const double* phi, double* M, double* dM, double* d2M) const {
    m_->inertia_second_derivatives(q, phi, M, dM, d2M);
  }
  void forward_kinematics(const double* q, double* T) const { m_->forward_kinematics(q, T); }
  void jacobian(const double* q, double* J) const { m_->jacobian(q, J); }
  void base_from_standard(const double* s, double* phi) const { m_->base_from_standard(s, phi); }
  void to_parent(const double* phi, double* parent_phi) const { m_->to_parent(phi, parent_phi); }
  void from_parent(const double* parent_phi, double* phi) const { m_->from_parent(parent_phi, phi); }

  // Checked conveniences over Eigen vectors (sizes checked, std::invalid_argument naming them).
  Eigen::MatrixXd regressor(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) const;
  Eigen::VectorXd inverse_dynamics(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                                   const Eigen::VectorXd& phi) const;
  Eigen::MatrixXd inertia(const Eigen::VectorXd& q, const Eigen::VectorXd& phi) const;
  Eigen::VectorXd base_from_standard(const Eigen::VectorXd& s) const;

 private:
  std::shared_ptr<const RobotLibrary> library_;  // keeps the functions loaded (null: linked in)
  const symoro_abi_model* m_;
  std::string robot_, variant_, description_;
  std::vector<ParameterInfo> parameters_;
  std::vector<StandardParameterInfo> standard_;
  std::vector<EffectParameterInfo> effects_;
  std::vector<FixedParameter> fixed_;
  std::vector<int> parent_index_;
  std::vector<JointInfo> joints_;
  std::vector<FrameInfo> frames_;
};

}  // namespace symoro::robot
