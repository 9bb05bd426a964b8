#include "derivative_functions.hpp"

#include <map>

#include "symoro/codegen/emitter.hpp"
#include "symoro/codegen/passes.hpp"

namespace symoro::codegen::detail {

namespace {

std::string str(int v) { return std::to_string(v); }

void bind_symbols(std::map<std::string, std::string>& inputs, const std::vector<std::string>& symbols,
                  const std::string& vector) {
  for (std::size_t k = 0; k < symbols.size(); ++k) inputs[symbols[k]] = vector + "[" + str(static_cast<int>(k)) + "]";
}

// d ID / d x_k for every k: [k][j] = d ID_j / d x_k.
std::vector<std::vector<NodeId>> columns(const DerivativeModel& m, const std::vector<std::string>& x) {
  std::vector<std::vector<NodeId>> out;
  for (const auto& s : x) out.push_back(differentiate(*m.graph, m.id, s));
  return out;
}

// Assignments target(j, k) = entries[k][j] (column-major lists), skipping zeros; every entry a root.
void assign_columns(const ExprGraph& g, const std::string& target, const std::vector<std::vector<NodeId>>& by_column,
                    std::vector<Assignment>& out, std::vector<NodeId>& roots) {
  for (std::size_t k = 0; k < by_column.size(); ++k)
    for (std::size_t j = 0; j < by_column[k].size(); ++j) {
      const NodeId v = by_column[k][j];
      roots.push_back(v);
      if (!g.is_constant(v, 0.0))
        out.push_back({target + "(" + str(static_cast<int>(j)) + ", " + str(static_cast<int>(k)) + ")", v});
    }
}

std::string size_checks(const std::vector<std::pair<std::string, std::size_t>>& args) {
  std::string s;
  for (const auto& [name, size] : args)
    s += "  eigen_assert(" + name + ".size() == " + str(static_cast<int>(size)) + ");\n";
  for (const auto& a : args) s += "  static_cast<void>(" + a.first + ");\n";
  return s;
}

}  // namespace

std::string inverse_dynamics_derivatives_code(const DerivativeModel& m, std::vector<FunctionSummary>& summary) {
  const ExprGraph& g = *m.graph;
  std::vector<Assignment> out;
  std::vector<NodeId> roots;
  for (int j = 0; j < m.n; ++j) {
    roots.push_back(m.id[j]);
    if (!g.is_constant(m.id[j], 0.0)) out.push_back({"d.tau(" + str(j) + ")", m.id[j]});
  }
  assign_columns(g, "d.dq", columns(m, m.q), out, roots);
  assign_columns(g, "d.dqd", columns(m, m.qd), out, roots);
  summary.push_back({"inverse_dynamics_derivatives", count_operations(g, roots)});
  std::map<std::string, std::string> inputs;
  bind_symbols(inputs, m.q, "q");
  bind_symbols(inputs, m.qd, "qd");
  bind_symbols(inputs, m.qdd, "qdd");
  bind_symbols(inputs, m.phi, "phi");

  std::string s;
  s += "// Inverse dynamics and its derivatives along the state, at (q, qd, qdd; phi). The others are\n"
       "// generated already: d tau / d qdd = M(q; phi) (inertia), d tau / d phi = W (regressor).\n";
  s += "template <class Scalar>\nstruct InverseDynamicsDerivatives {\n";
  s += "  Eigen::Matrix<Scalar, nq, 1> tau;   // ID(q, qd, qdd; phi)\n";
  s += "  Eigen::Matrix<Scalar, nq, nq> dq;   // d tau / d q\n";
  s += "  Eigen::Matrix<Scalar, nq, nq> dqd;  // d tau / d qd\n};\n\n";
  s += "template <class Q, class QD, class QDD, class Phi, class Scalar>\n";
  s +=
      "inline void inverse_dynamics_derivatives(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,\n"
      "                                         const Eigen::MatrixBase<QDD>& qdd, const Eigen::MatrixBase<Phi>& phi,\n"
      "                                         InverseDynamicsDerivatives<Scalar>& d) {\n";
  s += math_usings(g, roots);
  s += size_checks({{"q", m.q.size()}, {"qd", m.qd.size()}, {"qdd", m.qdd.size()}, {"phi", m.phi.size()}});
  s += "  d.tau.setZero();\n  d.dq.setZero();\n  d.dqd.setZero();\n";
  s += emit_body(g, inputs, out, "  ");
  s += "}\n\n";
  return s;
}

std::string forward_dynamics_derivatives_code(const DerivativeModel& m, std::vector<FunctionSummary>& summary) {
  const ExprGraph& g = *m.graph;
  // Stage 1: M (lower triangle) and h.
  std::vector<Assignment> first, second;
  std::vector<NodeId> first_roots, second_roots;
  for (int j = 0; j < m.n; ++j)
    for (int k = 0; k <= j; ++k) {
      first_roots.push_back(m.M[j][k]);
      if (!g.is_constant(m.M[j][k], 0.0)) first.push_back({"stage_M(" + str(j) + ", " + str(k) + ")", m.M[j][k]});
    }
  for (int j = 0; j < m.n; ++j) {
    first_roots.push_back(m.h[j]);
    if (!g.is_constant(m.h[j], 0.0)) first.push_back({"stage_h(" + str(j) + ")", m.h[j]});
  }
  // Stage 2, at the computed qdd: d ID / d q, d ID / d qd and W.
  assign_columns(g, "stage_dq", columns(m, m.q), second, second_roots);
  assign_columns(g, "stage_dqd", columns(m, m.qd), second, second_roots);
  std::vector<std::vector<NodeId>> W_columns(m.np, std::vector<NodeId>(m.n));
  for (int j = 0; j < m.n; ++j)
    for (int p = 0; p < m.np; ++p) W_columns[p][j] = m.W[j][p];
  assign_columns(g, "stage_W", W_columns, second, second_roots);
  std::vector<NodeId> all = first_roots;
  all.insert(all.end(), second_roots.begin(), second_roots.end());
  summary.push_back({"forward_dynamics_derivatives", count_operations(g, all)});

  std::map<std::string, std::string> inputs;
  bind_symbols(inputs, m.q, "q");
  bind_symbols(inputs, m.qd, "qd");
  bind_symbols(inputs, m.phi, "phi");
  bind_symbols(inputs, m.qdd, "d.qdd");  // stage 2 reads the solved accelerations
  BodyEmitter emitter(g, inputs, all, "  ");

  const std::string mat = "Eigen::Matrix<Scalar, nq, nq>";
  std::string s;
  s += "// Forward dynamics and all its derivatives at (q, qd, tau; phi), in one pass: M and h = ID(q, qd,\n"
       "// 0), M^-1 from one LDL^T, qdd = M^-1 (tau - h); then d ID / d(q, qd) and W at that qdd (sharing every\n"
       "// subexpression with M and h), and, differentiating ID(q, qd, qdd) = tau,\n"
       "//   d qdd / d q = -M^-1 d ID / d q,  d qdd / d qd = -M^-1 d ID / d qd,  d qdd / d tau = M^-1,\n"
       "//   d qdd / d phi = -M^-1 W(q, qd, qdd).\n";
  s += "template <class Scalar>\nstruct ForwardDynamicsDerivatives {\n";
  s += "  Eigen::Matrix<Scalar, nq, 1> qdd;\n";
  s += "  " + mat + " dq;    // d qdd / d q\n";
  s += "  " + mat + " dqd;   // d qdd / d qd\n";
  s += "  " + mat + " dtau;  // d qdd / d tau = M^-1\n";
  s += "  Eigen::Matrix<Scalar, nq, np> dphi;  // d qdd / d phi = -M^-1 W\n";
  s += "  Scalar min_pivot;  // the smallest pivot of M's (unpivoted) LDL^T factorization\n};\n\n";
  s += "// False (the derivatives unset) when M(q; phi) is not positive definite (min_pivot <= 0).\n";
  s += "template <class Q, class QD, class Tau, class Phi, class Scalar>\n";
  s +=
      "inline bool forward_dynamics_derivatives(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,\n"
      "                                         const Eigen::MatrixBase<Tau>& tau, const Eigen::MatrixBase<Phi>& phi,\n"
      "                                         ForwardDynamicsDerivatives<Scalar>& d) {\n";
  s += math_usings(g, all);
  s += size_checks({{"q", m.q.size()}, {"qd", m.qd.size()}, {"tau", m.tau.size()}, {"phi", m.phi.size()}});
  s += "  " + mat + " stage_M;\n  Eigen::Matrix<Scalar, nq, 1> stage_h;\n  stage_M.setZero();\n  stage_h.setZero();\n";
  s += emitter.emit(first);
  s += "  // M^-1 by an unpivoted LDL^T in plain loops (symoro/spd_inverse.hpp), the lower triangle.\n";
  s += "  d.min_pivot = Scalar(0);\n";
  s += "  if (!::symoro::spd_inverse(stage_M, d.dtau, d.min_pivot)) return false;\n";
  s += "  for (int k = 0; k < nq; ++k) stage_h(k) = Scalar(tau[k]) - stage_h(k);\n";
  s += "  d.qdd = d.dtau.lazyProduct(stage_h);\n";
  s += "  " + mat + " stage_dq, stage_dqd;\n  Eigen::Matrix<Scalar, nq, np> stage_W;\n";
  s += "  stage_dq.setZero();\n  stage_dqd.setZero();\n  stage_W.setZero();\n";
  s += emitter.emit(second);
  s += "  // Products at these fixed sizes: coefficient-wise (lazy) beats a blocked GEMM.\n";
  s += "  d.dq = -d.dtau.lazyProduct(stage_dq);\n";
  s += "  d.dqd = -d.dtau.lazyProduct(stage_dqd);\n";
  s += "  d.dphi = -d.dtau.lazyProduct(stage_W);\n";
  s += "  return true;\n}\n\n";
  return s;
}

std::string inertia_derivatives_code(const DerivativeModel& m, std::vector<FunctionSummary>& summary) {
  ExprGraph& g = *m.graph;
  std::vector<NodeId> lower;  // M's lower triangle, row by row
  for (int j = 0; j < m.n; ++j)
    for (int k = 0; k <= j; ++k) lower.push_back(m.M[j][k]);
  std::vector<Assignment> out;
  std::vector<NodeId> roots;
  // Both triangles of a symmetric matrix from its lower one.
  const auto assign = [&](const std::string& target, const std::vector<NodeId>& entries) {
    std::size_t i = 0;
    for (int j = 0; j < m.n; ++j)
      for (int k = 0; k <= j; ++k, ++i) {
        const NodeId v = entries[i];
        roots.push_back(v);
        if (g.is_constant(v, 0.0)) continue;
        out.push_back({target + "(" + str(j) + ", " + str(k) + ")", v});
        if (j != k) out.push_back({target + "(" + str(k) + ", " + str(j) + ")", v});
      }
  };
  assign("d.M", lower);
  for (int k = 0; k < m.n; ++k) assign("d.dq[" + str(k) + "]", differentiate(g, lower, m.q[k]));
  summary.push_back({"inertia_derivatives", count_operations(g, roots)});
  std::map<std::string, std::string> inputs;
  bind_symbols(inputs, m.q, "q");
  bind_symbols(inputs, m.phi, "phi");

  std::string s;
  s += "// The inertia matrix and its derivatives along q, d M / d q_k for every k (the PD audit's\n"
       "// gradients); in ceres::Jet scalars seeded on q it gives d2 M / d q_k d q_l as well.\n";
  s += "template <class Scalar>\nstruct InertiaDerivatives {\n";
  s += "  Eigen::Matrix<Scalar, nq, nq> M;\n";
  s += "  std::array<Eigen::Matrix<Scalar, nq, nq>, nq> dq;  // dq[k] = d M / d q_k\n};\n\n";
  s += "template <class Q, class Phi, class Scalar>\n";
  s += "inline void inertia_derivatives(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Phi>& phi,\n"
       "                                InertiaDerivatives<Scalar>& d) {\n";
  s += math_usings(g, roots);
  s += size_checks({{"q", m.q.size()}, {"phi", m.phi.size()}});
  s += "  d.M.setZero();\n  for (auto& x : d.dq) x.setZero();\n";
  s += emit_body(g, inputs, out, "  ");
  s += "}\n\n";
  return s;
}

}  // namespace symoro::codegen::detail
