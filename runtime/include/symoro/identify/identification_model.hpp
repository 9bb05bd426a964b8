// What identification needs of a robot model, behind one small virtual interface, so that the
// study (OLS/WLS, audit, SDP, CLIE, selection, rescue, validation) is compiled once for every
// robot. One implementation serves every model (loaded_model.hpp, over a ModelHandle): a robot
// library loaded at run time, or a generated Model linked in (identification_model-inl.hpp), of
// which only the generated kernels compile per model, into symoro::<robot>_identification.
// The generated functions are far longer than a virtual call, and every call here covers a
// whole run or a whole pose (bench/bench_clie.cpp: simulation through the interface).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/effect_table.hpp"
#include "symoro/identify/closed_loop.hpp"
#include "symoro/identify/inertia_function.hpp"
#include "symoro/identify/physical_projection.hpp"
#include "symoro/identify/regression.hpp"
#include "symoro/model_info.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/trajectory/sampled_reference.hpp"

namespace symoro::identify {

// The model's description (the generated model.hpp's constants, at run time).
struct ModelDescription {
  std::string robot;    // e.g. "crane_x7"
  std::string variant;  // "" for the robot's full model
  int nq = 0, np = 0;
  std::vector<ParameterInfo> parameters;  // phi's entries
  std::vector<JointInfo> joints;
  std::vector<StandardParameterInfo> standard;        // the argument of base_from_standard
  std::vector<FrameInfo> frames;                      // the modified-DH frames (symoro/mdh.hpp)
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  // in frame 0 (m/s^2): which way is down
};

// The inverse dynamics at one state and its derivatives along the state (nq x nq each).
struct StateDerivatives {
  Eigen::VectorXd tau;
  Eigen::MatrixXd dq, dqd, dqdd;  // d tau / d q, d qd, d qdd (the last is M(q; phi))
};

class IdentificationModel {
 public:
  virtual ~IdentificationModel() = default;
  virtual const ModelDescription& description() const = 0;

  // The stacked regression of one run's samples (regression.hpp).
  virtual Regression stack_regression(const preprocess::Samples& samples) const = 0;
  // phi of standard parameters s (description().standard's order; the effect parameters last).
  virtual Eigen::VectorXd base_from_standard(const Eigen::VectorXd& s) const = 0;
  // ID(q, qd, qdd; phi) at every sample: samples x nq.
  virtual Eigen::MatrixXd open_loop_torque(const preprocess::Samples& samples, const Eigen::VectorXd& phi) const = 0;
  // At one state (q, qd, qdd): tau = W phi, with the fixed parameters' torque when
  // `with_fixed` (then it is ID(q, qd, qdd; phi)), and its derivatives from the generated
  // inverse_dynamics_derivatives and inertia. Without the fixed torque it is linear in phi: for
  // phi = g it gives d (W g) / d state, what the gradient of an excitation criterion needs.
  virtual void state_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                                 const Eigen::VectorXd& phi, bool with_fixed, StateDerivatives& out) const = 0;
  // M(q; phi) and its derivatives for the audit and the SDP projection.
  virtual std::unique_ptr<InertiaFunction> inertia_function() const = 0;
  // The closed loop of one reference under the experiment's controller.
  virtual std::unique_ptr<ClosedLoop> closed_loop(const ClosedLoopSetup& setup,
                                                  const trajectory::SampledReference& reference) const = 0;

  // The physical path (physical_projection.hpp): the rigid body's and drives' standard
  // parameters consistent, a variant's effect parameters beside them (free, or >= 0 for a
  // friction level). A variant whose standard vector is not its full model's has none.
  virtual bool supports_physical_consistency() const = 0;
  virtual ConsistencyResult physical_check(const Eigen::VectorXd& phi) const = 0;
  // prior: standard parameters (description().standard's order) the projection leans towards
  // among the base vectors it cannot tell apart, with relative weight prior_weight (empty: zero,
  // the physical_consistency.hpp default).
  virtual PhysicalProjection physical_projection(const Eigen::VectorXd& phi0, const Eigen::MatrixXd& metric,
                                                 double clearance, const Eigen::VectorXd& prior = {},
                                                 double prior_weight = 1e-6) const = 0;
  // The export's solve (model_export.hpp): the consistent standard parameters nearest `prior`
  // that reproduce phi in the full model's base (consistency_target: a variant's fixed
  // parameters included, then its effect parameters), and the full model's base_from_standard
  // (the effect parameters passed through). A model without physical consistency throws
  // std::logic_error.
  virtual ConsistencyResult consistent_standard_parameters(const Eigen::VectorXd& phi, const Eigen::VectorXd& prior,
                                                           const ConsistencyOptions& options) const = 0;
  virtual Eigen::VectorXd consistency_target(const Eigen::VectorXd& phi) const = 0;
  virtual Eigen::VectorXd parent_base_from_standard(const Eigen::VectorXd& s) const = 0;
};

// The names of a model's effect parameters (offsets, friction laws, harmonics: the last entries
// of phi), which no URDF or MJCF field carries; empty for a rigid model.
inline std::vector<std::string> effect_parameter_names(const ModelDescription& d) {
  std::vector<std::string> names;
  for (const ParameterInfo& p : d.parameters)
    if (variant_adds_family(p.family)) names.emplace_back(p.name);
  return names;
}

// The interface of a generated Model, one shared instance per model. Defined in
// identification_model-inl.hpp and compiled for every model of a robot into the library
// symoro::<robot>_identification: link it (or include the -inl header to compile it here).
template <class Model>
std::shared_ptr<const IdentificationModel> identification_model();

}  // namespace symoro::identify
