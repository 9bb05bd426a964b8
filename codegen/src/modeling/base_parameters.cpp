#include "base_parameters.hpp"

#include <cmath>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>

#include <Eigen/Dense>

#include "newton_euler.hpp"
#include "symoro/codegen/graph_evaluator.hpp"
#include "symoro/codegen/passes.hpp"
#include "symoro/codegen/robot_spec.hpp"

namespace symoro::codegen::modeling {

namespace {

bool is_symbol(const ExprGraph& g, NodeId id) { return g.node(id).op == Op::Symbol; }

// A rigid body's inertial parameters (J about the frame's origin, first moment c, mass m) seen
// from another frame, x_new = R x + p: J' = R J R^T + 2 (p . c') I - c' p^T - p c'^T + m (|p|^2 I - p p^T)
// with c' = R c; c'' = c' + m p.
void add_transformed_body(ExprGraph& g, const Transform& t, const Mat3& J, const Vec3& c, NodeId m,
                          std::array<NodeId, 10>& into) {
  Mat3 RJ;
  for (int r = 0; r < 3; ++r) RJ[r] = transpose_times(g, J, t.R[r]);  // row r of R J (J symmetric)
  const Vec3 cr = times(g, t.R, c);
  const NodeId pc = dot(g, t.p, cr), pp = dot(g, t.p, t.p);
  auto entry = [&](int r, int k) {
    NodeId e = dot(g, RJ[r], t.R[k]);  // (R J R^T)_rk
    if (r == k) e = g.add(e, g.add(g.mul(g.constant(2.0), pc), g.mul(m, pp)));
    e = g.sub(e, g.add(g.mul(cr[r], t.p[k]), g.mul(t.p[r], cr[k])));
    return g.sub(e, g.mul(m, g.mul(t.p[r], t.p[k])));
  };
  const int slots[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int s = 0; s < 6; ++s) into[s] = g.add(into[s], entry(slots[s][0], slots[s][1]));
  for (int r = 0; r < 3; ++r) into[MX + r] = g.add(into[MX + r], g.add(cr[r], g.mul(m, t.p[r])));
  into[M] = g.add(into[M], m);
}

std::string slot_name(const char* family, int link) { return std::string(family) + "R" + std::to_string(link); }

}  // namespace

BaseParameters base_parameters(ExprGraph& g, const Description& d) {
  const int n = d.n;
  BaseParameters out;
  std::vector<LinkParameters> K = d.links;
  const NodeId zero = g.zero();
  std::set<std::string> taken(d.standard.begin(), d.standard.end());
  taken.insert(d.geometric_symbols.begin(), d.geometric_symbols.end());
  for (const auto& j : d.joints) taken.insert({j.q, j.qd, j.qdd, j.tau});
  // Names a grouped value that moves to the antecedent (an intermediate of regp.txt).
  auto name = [&](NodeId value, const char* family, int link) {
    if (g.is_constant(value) || is_symbol(g, value)) return value;
    const std::string s = slot_name(family, link);
    if (taken.count(s)) throw InputError(d.path, 0, 0, "the grouped parameter name '" + s + "' is already a symbol of the robot");
    taken.insert(s);
    out.definitions.emplace_back(s, value);
    return g.symbol(s);
  };

  // ---- the general grouping rules, last link first
  for (int j = n; j >= 1; --j) {
    const JointDescription& jd = d.joints[j - 1];
    auto& k = K[j - 1].inertial;
    const int i = jd.ant;
    if (jd.sigma == 0) {
      const NodeId yy = name(k[YY], "YY", j), mz = name(k[MZ], "MZ", j), m = name(k[M], "M", j);
      if (i > 0) {
        const Transform t = frame_transform(g, jd, zero, jd.r_n);
        const Mat3 J{Vec3{yy, zero, zero}, Vec3{zero, yy, zero}, Vec3{zero, zero, zero}};
        add_transformed_body(g, t, J, Vec3{zero, zero, mz}, m, K[i - 1].inertial);
      }
      k[XX] = g.sub(k[XX], yy);
      k[YY] = k[MZ] = k[M] = zero;
    } else {
      std::array<NodeId, 6> J6;
      const char* fam[6] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ"};
      for (int s = 0; s < 6; ++s) J6[s] = name(k[s], fam[s], j);
      if (i > 0) {
        const Transform t = frame_transform(g, jd, jd.theta_n, zero);
        const Mat3 J{Vec3{J6[0], J6[1], J6[2]}, Vec3{J6[1], J6[3], J6[4]}, Vec3{J6[2], J6[4], J6[5]}};
        add_transformed_body(g, Transform{t.R, Vec3{zero, zero, zero}}, J, Vec3{zero, zero, zero}, zero,
                             K[i - 1].inertial);
      }
      for (int s = 0; s < 6; ++s) k[s] = zero;
    }
  }

  // ---- the particular cases, numerically: one candidate symbol per nonzero slot
  struct Candidate {
    int link, slot;  // slot 0..9 inertial, 10 IA, 11 FV, 12 FS
    std::string symbol;
  };
  std::vector<Candidate> cand;
  std::vector<LinkParameters> probe(n);
  for (int j = 1; j <= n; ++j) {
    auto add = [&](int slot, NodeId value, NodeId& into) {
      if (g.is_constant(value, 0.0)) {
        into = zero;
        return;
      }
      const std::string s = "__candidate_" + std::to_string(cand.size());
      cand.push_back({j, slot, s});
      into = g.symbol(s);
    };
    for (int s = 0; s < 10; ++s) add(s, K[j - 1].inertial[s], probe[j - 1].inertial[s]);
    add(10, K[j - 1].ia, probe[j - 1].ia);
    add(11, K[j - 1].fv, probe[j - 1].fv);
    add(12, K[j - 1].fs, probe[j - 1].fs);
  }
  Evaluator tau(g, inverse_dynamics(g, d, probe));
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> generic(0.5, 1.5), state(-2.0, 2.0);
  const int states = 3 * static_cast<int>(cand.size()) / std::max(1, n) + 8;
  Eigen::MatrixXd W(states * n, cand.size());
  std::map<std::string, double> values;
  for (const auto& s : d.geometric_symbols) values[s] = generic(rng);
  for (int s = 0; s < states; ++s) {
    for (const auto& jd : d.joints) {
      values[jd.q] = state(rng);
      values[jd.qd] = state(rng);
      values[jd.qdd] = state(rng);
    }
    for (std::size_t c = 0; c < cand.size(); ++c) {
      for (const auto& o : cand) values[o.symbol] = 0;
      values[cand[c].symbol] = 1;
      const auto col = tau(values);
      for (int j = 0; j < n; ++j) W(s * n + j, static_cast<Eigen::Index>(c)) = col[j];
    }
    for (const auto& o : cand) values.erase(o.symbol);
  }
  const double scale = W.colwise().norm().maxCoeff();
  std::vector<bool> keep(cand.size(), true);
  for (std::size_t c = 0; c < cand.size(); ++c)
    if (W.col(c).norm() <= 1e-10 * scale) keep[c] = false;
  // A rotor inertia with the same column as its link's ZZ (M for a prismatic joint) joins it.
  for (std::size_t c = 0; c < cand.size(); ++c) {
    if (!keep[c] || cand[c].slot != 10) continue;
    const int j = cand[c].link;
    const int target = d.joints[j - 1].sigma == 0 ? ZZ : M;
    for (std::size_t o = 0; o < cand.size(); ++o) {
      if (!keep[o] || cand[o].link != j || cand[o].slot != target) continue;
      if ((W.col(c) - W.col(o)).norm() <= 1e-10 * scale) {
        K[j - 1].inertial[target] = g.add(K[j - 1].inertial[target], K[j - 1].ia);
        keep[c] = false;
        out.notes.push_back("IA" + std::to_string(j) + " is grouped with " + kInertialFamilies[target] + std::to_string(j));
      }
    }
  }
  std::vector<int> kept;
  for (std::size_t c = 0; c < cand.size(); ++c)
    if (keep[c]) kept.push_back(static_cast<int>(c));
  Eigen::MatrixXd Wk(W.rows(), kept.size());
  for (std::size_t c = 0; c < kept.size(); ++c) Wk.col(c) = W.col(kept[c]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Wk, Eigen::ComputeFullV);
  const auto& sv = svd.singularValues();
  int rank = 0;
  for (Eigen::Index i = 0; i < sv.size(); ++i) rank += sv(i) > 1e-9 * sv(0);
  auto slot_label = [&](const Candidate& c) {
    const char* fam = c.slot < 10 ? kInertialFamilies[c.slot] : c.slot == 10 ? "IA" : c.slot == 11 ? "FV" : "FS";
    return std::string(fam) + std::to_string(c.link);
  };
  if (rank < static_cast<int>(kept.size())) {
    std::string which;
    const Eigen::VectorXd v = svd.matrixV().col(kept.size() - 1);
    for (std::size_t c = 0; c < kept.size(); ++c)
      if (std::abs(v(c)) > 1e-6) which += (which.empty() ? "" : ", ") + slot_label(cand[kept[c]]);
    throw InputError(d.path, 0, 0,
                     "the grouped parameters " + which +
                         " are still linearly dependent: this geometry needs a grouping rule symoroc does not apply "
                         "(the general rules and the zero and rotor-inertia cases only)");
  }

  // ---- the base parameters: a slot keeps its standard name when nothing was grouped into it
  out.links.assign(n, LinkParameters{});
  for (auto& l : out.links) {
    l.inertial.fill(zero);
    l.ia = l.fv = l.fs = zero;
  }
  for (const int c : kept) {
    const Candidate& cd = cand[c];
    LinkParameters& src = K[cd.link - 1];
    LinkParameters& dst = out.links[cd.link - 1];
    const NodeId value = cd.slot < 10 ? src.inertial[cd.slot] : cd.slot == 10 ? src.ia : cd.slot == 11 ? src.fv : src.fs;
    const NodeId own = cd.slot < 10 ? d.links[cd.link - 1].inertial[cd.slot]
                                    : cd.slot == 10 ? d.links[cd.link - 1].ia : cd.slot == 11 ? d.links[cd.link - 1].fv : d.links[cd.link - 1].fs;
    NodeId sym = value;
    if (value != own) {
      const std::string s = slot_name(kInertialFamilies[cd.slot], cd.link);  // IA, FV, FS never change
      if (taken.count(s)) {
        // Named already as an intermediate: that definition is this value (the slot did not change since).
        bool same = false;
        for (const auto& [nm, v] : out.definitions) same = same || (nm == s && v == value);
        if (!same) throw InputError(d.path, 0, 0, "the grouped parameter name '" + s + "' is already a symbol of the robot");
      } else {
        taken.insert(s);
        out.definitions.emplace_back(s, value);
      }
      sym = g.symbol(s);
    }
    NodeId& into = cd.slot < 10 ? dst.inertial[cd.slot] : cd.slot == 10 ? dst.ia : cd.slot == 11 ? dst.fv : dst.fs;
    into = sym;
    out.names.push_back(g.symbol_name(g.node(sym).symbol));
  }
  int dropped = 0;
  for (std::size_t c = 0; c < cand.size(); ++c) dropped += !keep[c];
  out.notes.push_back(std::to_string(out.names.size()) + " base parameters; " + std::to_string(dropped) +
                      " grouped parameters have no effect or joined another");
  return out;
}

}  // namespace symoro::codegen::modeling
