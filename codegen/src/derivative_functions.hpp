// The generated derivative functions of a model (generate/derivative_headers.cpp writes the
// headers around them): inverse_dynamics_derivatives and forward_dynamics_derivatives,
// differentiated on the expression graph (passes.hpp differentiate) and emitted with the value in
// one body, so that every subexpression (the kinematics, the trigonometry) is computed once for
// all outputs.
#pragma once

#include <string>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"
#include "symoro/codegen/generator.hpp"

namespace symoro::codegen::detail {

// One model's expressions, as graph nodes, and its symbols' names.
struct DerivativeModel {
  ExprGraph* graph = nullptr;
  int n = 0, np = 0;
  std::vector<std::string> q, qd, qdd, tau, phi;  // symbol names; phi: the identified parameters
  std::vector<NodeId> id;                         // tau = ID(q, qd, qdd; phi), with effects
  std::vector<std::vector<NodeId>> M;             // n x n inertia matrix M(q; phi)
  std::vector<NodeId> h;                          // ID(q, qd, 0; phi)
  std::vector<std::vector<NodeId>> W;             // n x np: d ID / d phi (the regressor)
};

// The struct InverseDynamicsDerivatives<Scalar> and the function filling it (tau, d tau / d q,
// d tau / d qd); its operation count goes to `summary`.
std::string inverse_dynamics_derivatives_code(const DerivativeModel& m, std::vector<FunctionSummary>& summary);

// The struct ForwardDynamicsDerivatives<Scalar> and the function filling it (qdd and d qdd / d q,
// d qdd / d qd, d qdd / d tau = M^-1, d qdd / d phi = -M^-1 W): M and h, one LDLT of M, then
// d ID / d(q, qd) and W at the computed qdd.
std::string forward_dynamics_derivatives_code(const DerivativeModel& m, std::vector<FunctionSummary>& summary);

// The struct InertiaDerivatives<Scalar> and the function filling it (M and d M / d q_k for every
// k), for the PD audit's gradients; in Jets over q it gives the second derivatives too.
std::string inertia_derivatives_code(const DerivativeModel& m, std::vector<FunctionSummary>& summary);

}  // namespace symoro::codegen::detail
