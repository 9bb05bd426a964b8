// The closed-loop simulation CLIE fits through (paper Fig. clie_block): the identified model's
// forward dynamics driven by the same fixed FF+PD controller, sample-and-hold and bus delay as
// the experiment, with forward sensitivities d tau / d phi (no finite differences): by default
// O(h^2) from the exact derivatives of the discrete simulation, or those exactly
// (ClosedLoopSetup::exact_sensitivities).
//
// Timing of cycle k (period T, sampling instant t_k = k T, no jitter): q is sampled, the
// controller computes a command that takes effect at t_k + delay and is held until the next
// one does. The torque recorded for cycle k is the command in effect at t_k (the previous
// one), which is what a log row records (twin/simulator.hpp). Before t = 0 the first reference
// is held for pre_roll seconds, starting from rest at it, as in the experiment.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/control/description.hpp"
#include "symoro/control/ffpd.hpp"
#include "symoro/model_info.hpp"
#include "symoro/preprocess/channels.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::identify {

struct ClosedLoopSetup {
  control::FfpdGains gains;       // the experiment's controller (realization parameters, gains)
  double delay = 0.0009;          // s from sampling to the command taking effect
  double pre_roll = 0.5;          // s holding the first reference before t = 0
  int substeps = 1;               // integration steps per hold interval
  double divergence_error = 0.5;  // rad: a tracking error |q_ref - q| beyond it is divergence
  // Integration steps end at every sampling instant (the twin's split of a cycle into two
  // holds) instead of spanning each hold with q(t_k) read inside the step
  // (closed_loop_model.hpp): twice the work for no accuracy that matters.
  bool split_at_sampling = false;
  // The sensitivities' d qdd / d(q, qd, tau, phi) (the generated forward_dynamics_derivatives)
  // at each Heun stage (the exact derivative of the discrete map, twice the derivative work), or,
  // by default, once per step at its midpoint (closed_loop_model.hpp: d tau ~6e-5 relative from
  // the exact one).
  bool exact_sensitivities = false;
};

// The experiment's controller and timing, from the robot's controller description.
ClosedLoopSetup closed_loop_setup(const control::ControllerDescription& controller, double pre_roll = 0.5);

// Why a simulation stopped early.
struct Divergence {
  bool diverged = false;
  double time = 0;               // s
  int joint = -1;                // 0-based, -1 when not joint-specific
  std::string reason;            // e.g. "tracking error 0.62 rad", "M not positive definite", "not finite"
  std::string describe() const;  // one line for reports
};

// A closed-loop simulation of one reference, seen through the model-independent interface that
// CLIE, validation and the study are compiled against once for every robot. The implementation
// for a generated Model is ClosedLoopSimulator<Model> (closed_loop_model.hpp), whose fixed-size
// loop is the only part compiled per model.
class ClosedLoop {
 public:
  // Takes d tau / d phi one cycle at a time, in order: row k's nq * np values, d tau_j / d phi_i
  // at j * np + i (so that a caller can reduce them as they come instead of storing them all).
  class SensitivityRows {
   public:
    virtual ~SensitivityRows() = default;
    virtual void row(const double* dtau) = 0;
  };

  virtual ~ClosedLoop() = default;
  virtual int joints() const = 0;
  // The model's parameters: the entries of phi, in order.
  virtual const std::vector<ParameterInfo>& parameter_info() const = 0;
  int parameters() const { return static_cast<int>(parameter_info().size()); }
  virtual int cycles() const = 0;  // K + 1 with K = round(duration / T)
  virtual const ClosedLoopSetup& setup() const = 0;
  double period() const { return setup().gains.period; }
  // tau: cycles() x nq, row k = the torque recorded at cycle k. With dtau (not null):
  // cycles() x (nq * np), column j * np + i = d tau_j / d phi_i. Returns false (and fills *why
  // when given) when the simulation diverges; tau is then unusable. With q (not null): the
  // sampled q (cycles() x nq, row k = q(t_k), what the controller saw).
  virtual bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, preprocess::Channels* dtau,
                        Divergence* why, preprocess::Channels* q) const = 0;
  bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, preprocess::Channels* dtau,
                Divergence* why) const {
    return simulate(phi, tau, dtau, why, nullptr);
  }
  // The same with d tau / d phi handed to `dtau` row by row (cycles() rows unless it diverges).
  virtual bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, SensitivityRows& dtau,
                        Divergence* why) const = 0;
};

}  // namespace symoro::identify
