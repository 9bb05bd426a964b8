// A robot model's inverse dynamics and mass matrix for the control loop (controller.hpp), through
// its handle: what dynid control uses for every robot.
#include <stdexcept>
#include <string>

#include "symoro/hardware/controller.hpp"

namespace symoro::hardware {
namespace {

void check_size(const robot::ModelHandle& model, const Eigen::VectorXd& phi) {
  if (phi.size() != model.np())
    throw std::invalid_argument("model feedforward: " + std::to_string(phi.size()) + " parameters for model '" +
                                model.label() + "' of robot '" + model.robot() + "', which has " +
                                std::to_string(model.np()));
}

}  // namespace

std::function<void(const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd&, Eigen::VectorXd&)>
model_feedforward(const robot::ModelHandle& model, const Eigen::VectorXd& phi) {
  check_size(model, phi);
  return [model, phi](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                      Eigen::VectorXd& tau) {
    tau.resize(model.nq());
    model.inverse_dynamics(q.data(), qd.data(), qdd.data(), phi.data(), tau.data());
  };
}

std::function<void(const Eigen::VectorXd&, Eigen::MatrixXd&)> model_inertia(const robot::ModelHandle& model,
                                                                            const Eigen::VectorXd& phi) {
  check_size(model, phi);
  return [model, phi](const Eigen::VectorXd& q, Eigen::MatrixXd& M) {
    M.resize(model.nq(), model.nq());
    model.inertia(q.data(), phi.data(), M.data());
  };
}

}  // namespace symoro::hardware
