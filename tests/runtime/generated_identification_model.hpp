// The study's IdentificationModel of a generated Model written out in fixed sizes over the
// Model's own templates (stack_regression<Model>, ClosedLoopSimulator<Model>, the physical path
// <Model>): what the runtime instantiated per model before it was compiled once over ModelHandle
// (identification_model-inl.hpp). Kept for the tests as an independent second implementation: the
// runtime's IdentificationModel must equal it bit for bit.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "symoro/identify/detail/closed_loop_model.hpp"
#include "symoro/identify/detail/inertia_function_model.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/physical_projection.hpp"
#include "symoro/identify/regression.hpp"
#include "symoro/study/validation.hpp"

namespace symoro::identify {
namespace detail {

template <class Model>
class GeneratedIdentificationModel final : public IdentificationModel {
 public:
  GeneratedIdentificationModel() {
    d_.robot = Model::robot_name;
    d_.variant = Model::variant_name;
    d_.nq = Model::nq;
    d_.np = Model::np;
    d_.parameters.assign(Model::parameters.begin(), Model::parameters.end());
    d_.joints.assign(Model::joints.begin(), Model::joints.end());
    d_.standard.assign(Model::standard_parameters.begin(), Model::standard_parameters.end());
    d_.frames.assign(Model::frames.begin(), Model::frames.end());
    d_.gravity = Eigen::Vector3d(Model::gravity[0], Model::gravity[1], Model::gravity[2]);
    for (const auto& f : Model::fixed_parameters) has_fixed_ = has_fixed_ || f.value != 0;
  }
  const ModelDescription& description() const override { return d_; }

  Regression stack_regression(const preprocess::Samples& samples) const override {
    return identify::stack_regression<Model>(samples);
  }
  Eigen::VectorXd base_from_standard(const Eigen::VectorXd& s) const override {
    if (s.size() != Model::ns)
      throw std::invalid_argument("base_from_standard: " + std::to_string(s.size()) + " standard parameters for " +
                                  std::to_string(Model::ns));
    return Model::base_from_standard(Eigen::Matrix<double, Model::ns, 1>(s));
  }
  Eigen::MatrixXd open_loop_torque(const preprocess::Samples& samples, const Eigen::VectorXd& phi) const override {
    return study::open_loop_torque<Model>(samples, phi);
  }
  void state_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                         const Eigen::VectorXd& phi, bool with_fixed, StateDerivatives& out) const override {
    using V = Eigen::Matrix<double, Model::nq, 1>;
    const V Q = q, QD = qd, QDD = qdd;
    const Eigen::Matrix<double, Model::np, 1> P = phi;
    typename Model::template InverseDynamicsDerivatives<double> d;
    Model::inverse_dynamics_derivatives(Q, QD, QDD, P, d);
    Eigen::Matrix<double, Model::nq, Model::nq> M;
    Model::inertia(Q, P, M);
    out.tau = d.tau;
    out.dq = d.dq;
    out.dqd = d.dqd;
    out.dqdd = M;
    if (has_fixed_ && !with_fixed) {  // the fixed parameters' part, affine: subtract it at phi = 0
      const Eigen::Matrix<double, Model::np, 1> zero = Eigen::Matrix<double, Model::np, 1>::Zero();
      Model::inverse_dynamics_derivatives(Q, QD, QDD, zero, d);
      Model::inertia(Q, zero, M);
      out.tau -= d.tau;
      out.dq -= d.dq;
      out.dqd -= d.dqd;
      out.dqdd -= M;
    }
  }
  std::unique_ptr<InertiaFunction> inertia_function() const override { return make_inertia_function<Model>(); }
  std::unique_ptr<ClosedLoop> closed_loop(const ClosedLoopSetup& setup,
                                          const trajectory::SampledReference& reference) const override {
    return std::make_unique<ClosedLoopSimulator<Model>>(setup, reference);
  }

  bool supports_physical_consistency() const override { return identify::supports_physical_consistency<Model>(); }
  ConsistencyResult physical_check(const Eigen::VectorXd& phi) const override {
    return identify::physical_check<Model>(phi);
  }
  PhysicalProjection physical_projection(const Eigen::VectorXd& phi0, const Eigen::MatrixXd& metric, double clearance,
                                         const Eigen::VectorXd& prior, double prior_weight) const override {
    ConsistencyOptions options;
    options.prior_regularization = prior_weight;
    return identify::physical_projection<Model>(phi0, prior, metric, clearance, options);
  }
  ConsistencyResult consistent_standard_parameters(const Eigen::VectorXd& phi, const Eigen::VectorXd& prior,
                                                   const ConsistencyOptions& options) const override {
    if constexpr (identify::supports_physical_consistency<Model>())
      return identify::consistent_standard_parameters<Model>(phi, prior, options);
    else
      throw std::logic_error(unsupported());
  }
  Eigen::VectorXd consistency_target(const Eigen::VectorXd& phi) const override {
    if constexpr (identify::supports_physical_consistency<Model>())
      return identify::consistency_target<Model>(phi);
    else
      throw std::logic_error(unsupported());
  }
  Eigen::VectorXd parent_base_from_standard(const Eigen::VectorXd& s) const override {
    if constexpr (identify::supports_physical_consistency<Model>()) {
      using Parent = typename Model::Parent;
      constexpr int ne = identify::detail::effect_count<Model>();
      Eigen::VectorXd target(Parent::np + ne);
      target.head(Parent::np) = Parent::base_from_standard(Eigen::Matrix<double, Parent::ns, 1>(s.head(Parent::ns)));
      target.tail(ne) = s.tail(ne);
      return target;
    } else {
      throw std::logic_error(unsupported());
    }
  }

 private:
  static std::string unsupported() {
    return std::string("the ") + Model::variant_name + " model's standard vector is not its full model's";
  }
  ModelDescription d_;
  bool has_fixed_ = false;
};

}  // namespace detail

template <class Model>
std::shared_ptr<const IdentificationModel> generated_identification_model() {
  return std::make_shared<detail::GeneratedIdentificationModel<Model>>();
}

}  // namespace symoro::identify
