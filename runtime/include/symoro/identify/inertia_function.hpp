// M(q; phi) of a generated model seen through a small type-erased interface, so that the PD
// audit and the SDP projection are compiled once for every robot. M is affine in phi:
//   M(q; phi) = C(q) + sum_i phi_i L_i(q)     (the generated inertia_basis)
// and its derivatives in q are exact (ceres::Jet through the generated inertia()).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "symoro/model_info.hpp"

namespace symoro::identify {

// The box of joint angles the all-pose audit covers (rad), one interval per joint.
struct AuditDomain {
  Eigen::VectorXd lower, upper;
  int joints() const { return static_cast<int>(lower.size()); }
};

// The audit domain of a model's joints (JointInfo::audit_lower/audit_upper, robot.yaml).
inline AuditDomain audit_domain(const std::vector<JointInfo>& joints) {
  AuditDomain d;
  const auto n = static_cast<Eigen::Index>(joints.size());
  d.lower.resize(n);
  d.upper.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    d.lower(j) = joints[static_cast<std::size_t>(j)].audit_lower;
    d.upper(j) = joints[static_cast<std::size_t>(j)].audit_upper;
  }
  return d;
}

// The same for a generated Model.
template <class Model>
AuditDomain audit_domain() {
  return audit_domain(std::vector<JointInfo>(Model::joints.begin(), Model::joints.end()));
}

class InertiaFunction {
 public:
  virtual ~InertiaFunction() = default;
  virtual int joints() const = 0;
  virtual int parameters() const = 0;
  // M(q; phi), joints x joints.
  virtual void inertia(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M) const = 0;
  // C(q) and L_i(q), i = 0..parameters()-1 (resized by the call).
  virtual void basis(const Eigen::VectorXd& q, Eigen::MatrixXd& constant,
                     std::vector<Eigen::MatrixXd>& linear) const = 0;
  // M(q; phi) and dM/dq_k for k = 0..joints()-1, exact (forward-mode Jets).
  virtual void inertia_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                                   std::vector<Eigen::MatrixXd>& dM_dq) const = 0;
  // The same plus d2M/dq_k dq_l at d2M_dq2[k * joints() + l], exact. Returns false when an
  // implementation has no second derivatives (the PD audit then approximates its Hessian).
  virtual bool inertia_second_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                                          std::vector<Eigen::MatrixXd>& dM_dq,
                                          std::vector<Eigen::MatrixXd>& d2M_dq2) const {
    static_cast<void>(q), static_cast<void>(phi), static_cast<void>(M), static_cast<void>(dM_dq),
        static_cast<void>(d2M_dq2);
    return false;
  }
};

// Defined in inertia_function_model.hpp (templates over a generated Model).
template <class Model>
std::unique_ptr<InertiaFunction> make_inertia_function();

}  // namespace symoro::identify
