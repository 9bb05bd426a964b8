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

// A candidate base parameter of the particular cases: one symbol per nonzero slot of a link.
struct Candidate {
  int link, slot;  // slot 0..9 inertial, 10 IA, 11 FV, 12 FS
  std::string symbol;
};

std::string slot_label(const Candidate& c) {
  const char* fam = c.slot < 10 ? kInertialFamilies[c.slot] : c.slot == 10 ? "IA" : c.slot == 11 ? "FV" : "FS";
  return std::string(fam) + std::to_string(c.link);
}

// A link's slot (0..9 inertial, 10 IA, 11 FV, 12 FS).
NodeId& slot_of(LinkParameters& l, int slot) {
  return slot < 10 ? l.inertial[slot] : slot == 10 ? l.ia : slot == 11 ? l.fv : l.fs;
}

// The grouping of a robot's standard parameters into its base parameters, in three steps: the
// general rules (symbolic), the particular cases (numeric, on the inverse dynamics' columns), and
// the base parameters' names.
class Grouping {
 public:
  Grouping(ExprGraph& g, const Description& d) : g_(g), d_(d), K_(d.links), zero_(g.zero()) {
    taken_.insert(d.standard.begin(), d.standard.end());
    taken_.insert(d.geometric_symbols.begin(), d.geometric_symbols.end());
    for (const auto& j : d.joints) taken_.insert({j.q, j.qd, j.qdd, j.tau});
  }

  BaseParameters run() {
    general_rules();
    const Eigen::MatrixXd W = candidate_columns();
    drop_and_join(W);
    check_rank(W);
    name_base_parameters();
    return std::move(out_);
  }

 private:
  // Names a grouped value that moves to the antecedent (an intermediate of regp.txt).
  NodeId name(NodeId value, const char* family, int link) {
    if (g_.is_constant(value) || is_symbol(g_, value)) return value;
    const std::string s = slot_name(family, link);
    if (taken_.count(s))
      throw InputError(d_.path, 0, 0, "the grouped parameter name '" + s + "' is already a symbol of the robot");
    taken_.insert(s);
    out_.definitions.emplace_back(s, value);
    return g_.symbol(s);
  }

  // The general grouping rules, last link first: a revolute joint's YY, MZ, M and a prismatic
  // joint's inertia move to the antecedent.
  void general_rules() {
    ExprGraph& g = g_;
    const NodeId zero = zero_;
    for (int j = d_.n; j >= 1; --j) {
      const JointDescription& jd = d_.joints[j - 1];
      auto& k = K_[j - 1].inertial;
      const int i = jd.ant;
      if (jd.sigma == 0) {
        const NodeId yy = name(k[YY], "YY", j), mz = name(k[MZ], "MZ", j), m = name(k[M], "M", j);
        if (i > 0) {
          const Transform t = frame_transform(g, jd, zero, jd.r_n);
          const Mat3 J{Vec3{yy, zero, zero}, Vec3{zero, yy, zero}, Vec3{zero, zero, zero}};
          add_transformed_body(g, t, J, Vec3{zero, zero, mz}, m, K_[i - 1].inertial);
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
                               K_[i - 1].inertial);
        }
        for (int s = 0; s < 6; ++s) k[s] = zero;
      }
    }
  }

  // The particular cases, numerically: one candidate symbol per nonzero slot, and the inverse
  // dynamics' column of each at generic geometry and random states.
  Eigen::MatrixXd candidate_columns() {
    const int n = d_.n;
    std::vector<LinkParameters> probe(n);
    for (int j = 1; j <= n; ++j) {
      auto add = [&](int slot, NodeId value, NodeId& into) {
        if (g_.is_constant(value, 0.0)) {
          into = zero_;
          return;
        }
        const std::string s = "__candidate_" + std::to_string(cand_.size());
        cand_.push_back({j, slot, s});
        into = g_.symbol(s);
      };
      for (int s = 0; s < 10; ++s) add(s, K_[j - 1].inertial[s], probe[j - 1].inertial[s]);
      add(10, K_[j - 1].ia, probe[j - 1].ia);
      add(11, K_[j - 1].fv, probe[j - 1].fv);
      add(12, K_[j - 1].fs, probe[j - 1].fs);
    }
    Evaluator tau(g_, inverse_dynamics(g_, d_, probe));
    std::mt19937_64 rng(20261126);
    std::uniform_real_distribution<double> generic(0.5, 1.5), state(-2.0, 2.0);
    const int states = 3 * static_cast<int>(cand_.size()) / std::max(1, n) + 8;
    Eigen::MatrixXd W(states * n, cand_.size());
    std::map<std::string, double> values;
    for (const auto& s : d_.geometric_symbols) values[s] = generic(rng);
    for (int s = 0; s < states; ++s) {
      for (const auto& jd : d_.joints) {
        values[jd.q] = state(rng);
        values[jd.qd] = state(rng);
        values[jd.qdd] = state(rng);
      }
      for (std::size_t c = 0; c < cand_.size(); ++c) {
        for (const auto& other : cand_) values[other.symbol] = 0;
        values[cand_[c].symbol] = 1;
        const auto col = tau(values);
        for (int j = 0; j < n; ++j) W(s * n + j, static_cast<Eigen::Index>(c)) = col[j];
      }
      for (const auto& other : cand_) values.erase(other.symbol);
    }
    return W;
  }

  // Drops the candidates without effect, and joins a rotor inertia whose column is its link's ZZ
  // (M for a prismatic joint) to it; kept_ lists the rest.
  void drop_and_join(const Eigen::MatrixXd& W) {
    const double scale = W.colwise().norm().maxCoeff();
    keep_.assign(cand_.size(), true);
    for (std::size_t c = 0; c < cand_.size(); ++c)
      if (W.col(c).norm() <= 1e-10 * scale) keep_[c] = false;
    for (std::size_t c = 0; c < cand_.size(); ++c) {
      if (!keep_[c] || cand_[c].slot != 10) continue;
      const int j = cand_[c].link;
      const int target = d_.joints[j - 1].sigma == 0 ? ZZ : M;
      for (std::size_t o = 0; o < cand_.size(); ++o) {
        if (!keep_[o] || cand_[o].link != j || cand_[o].slot != target) continue;
        if ((W.col(c) - W.col(o)).norm() <= 1e-10 * scale) {
          K_[j - 1].inertial[target] = g_.add(K_[j - 1].inertial[target], K_[j - 1].ia);
          keep_[c] = false;
          out_.notes.push_back("IA" + std::to_string(j) + " is grouped with " + kInertialFamilies[target] +
                               std::to_string(j));
        }
      }
    }
    for (std::size_t c = 0; c < cand_.size(); ++c)
      if (keep_[c]) kept_.push_back(static_cast<int>(c));
  }

  // The kept columns must be independent: else a grouping rule symoroc lacks is needed.
  void check_rank(const Eigen::MatrixXd& W) const {
    Eigen::MatrixXd Wk(W.rows(), kept_.size());
    for (std::size_t c = 0; c < kept_.size(); ++c) Wk.col(c) = W.col(kept_[c]);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(Wk, Eigen::ComputeFullV);
    const auto& sv = svd.singularValues();
    int rank = 0;
    for (Eigen::Index i = 0; i < sv.size(); ++i) rank += sv(i) > 1e-9 * sv(0);
    if (rank < static_cast<int>(kept_.size())) {
      std::string which;
      const Eigen::VectorXd v = svd.matrixV().col(kept_.size() - 1);
      for (std::size_t c = 0; c < kept_.size(); ++c)
        if (std::abs(v(c)) > 1e-6) which += (which.empty() ? "" : ", ") + slot_label(cand_[kept_[c]]);
      throw InputError(d_.path, 0, 0,
                       "the grouped parameters " + which +
                           " are still linearly dependent: this geometry needs a grouping rule symoroc does not apply "
                           "(the general rules and the zero and rotor-inertia cases only)");
    }
  }

  // The base parameters: a slot keeps its standard name when nothing was grouped into it.
  void name_base_parameters() {
    out_.links.assign(d_.n, LinkParameters{});
    for (auto& l : out_.links) {
      l.inertial.fill(zero_);
      l.ia = l.fv = l.fs = zero_;
    }
    for (const int c : kept_) {
      const Candidate& cd = cand_[c];
      const NodeId value = slot_of(K_[cd.link - 1], cd.slot);
      LinkParameters standard = d_.links[cd.link - 1];
      const NodeId own = slot_of(standard, cd.slot);
      NodeId sym = value;
      if (value != own) {
        const std::string s = slot_name(kInertialFamilies[cd.slot], cd.link);  // IA, FV, FS never change
        if (taken_.count(s)) {
          // Named already as an intermediate: that definition is this value (the slot did not change since).
          bool same = false;
          for (const auto& [nm, v] : out_.definitions) same = same || (nm == s && v == value);
          if (!same)
            throw InputError(d_.path, 0, 0, "the grouped parameter name '" + s + "' is already a symbol of the robot");
        } else {
          taken_.insert(s);
          out_.definitions.emplace_back(s, value);
        }
        sym = g_.symbol(s);
      }
      slot_of(out_.links[cd.link - 1], cd.slot) = sym;
      out_.names.push_back(g_.symbol_name(g_.node(sym).symbol));
    }
    int dropped = 0;
    for (std::size_t c = 0; c < cand_.size(); ++c) dropped += !keep_[c];
    out_.notes.push_back(std::to_string(out_.names.size()) + " base parameters; " + std::to_string(dropped) +
                         " grouped parameters have no effect or joined another");
  }

  ExprGraph& g_;
  const Description& d_;
  BaseParameters out_;
  std::vector<LinkParameters> K_;  // the links' parameters as the grouping moves them
  NodeId zero_;
  std::set<std::string> taken_;  // every symbol of the robot, and every name given so far
  std::vector<Candidate> cand_;
  std::vector<bool> keep_;
  std::vector<int> kept_;
};

}  // namespace

BaseParameters base_parameters(ExprGraph& g, const Description& d) { return Grouping(g, d).run(); }

}  // namespace symoro::codegen::modeling
