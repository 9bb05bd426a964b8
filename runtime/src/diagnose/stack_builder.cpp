// The design stack by parallel filtering (stack_builder.hpp), compiled once for every robot: the
// models' regressors come through a StackModel.
#include "symoro/diagnose/stack_builder.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "symoro/diagnose/effects.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::diagnose {

namespace {

// The stack's description of the model: joint and parameter names, where each joint's rotor
// inertia and viscous friction sit, the payload's map, and the full model's parameters the
// identified one lacks (their indices in the full regressor returned).
std::vector<int> describe_model(const StackModel& m, DesignStack& d) {
  const int n = m.nq, p = m.np, pf = static_cast<int>(m.full_parameters.size());
  for (const auto& j : m.joints) d.joint_names.push_back(j.name);
  for (const auto& par : m.parameters) d.parameters.push_back(par.name);
  d.rotor_inertia_index = Eigen::VectorXd::Constant(n, -1);
  d.viscous_index = Eigen::VectorXd::Constant(n, -1);
  for (int i = 0; i < p; ++i) {
    const auto& par = m.parameters[static_cast<std::size_t>(i)];
    const std::string fam = par.family;
    if (par.joint >= 1 && par.joint <= n && fam == "IA") d.rotor_inertia_index(par.joint - 1) = i;
    if (par.joint >= 1 && par.joint <= n && fam == "FV") d.viscous_index(par.joint - 1) = i;
  }
  // The payload's base parameters per unit of the last massive link's M, MX, MY, MZ.
  for (const auto& par : m.standard)
    if (std::string(par.family) == "M") d.payload_link = std::max(d.payload_link, par.joint);
  if (d.payload_link > 0) {
    const std::string families[] = {"M", "MX", "MY", "MZ"};
    d.payload_map = Eigen::MatrixXd::Zero(p, 4);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < m.ns; ++k) {
        const auto& par = m.standard[static_cast<std::size_t>(k)];
        if (par.joint != d.payload_link || families[c] != par.family) continue;
        Eigen::VectorXd unit = Eigen::VectorXd::Zero(m.ns), column(p);
        unit(k) = 1;
        m.base_from_standard(unit.data(), column.data());
        d.payload_map.col(c) = column;
      }
  }
  std::vector<int> extra;
  for (int i = 0; i < pf; ++i) {
    bool identified = false;
    const ParameterInfo& full = m.full_parameters[static_cast<std::size_t>(i)];
    for (const auto& par : m.parameters) identified |= std::string(par.name) == full.name;
    if (identified) continue;
    extra.push_back(i);
    d.full_extra_names.push_back(full.name);
    d.full_extra_families.push_back(full.family);
    d.full_extra_joints.push_back(full.joint);
  }
  return extra;
}

// The sample-local candidates, and the friction a named joint's is chosen from again
// (friction_smoothing.hpp), each once.
std::vector<Candidate> sample_local_candidates(const DesignStack& d, const CandidateOptions& options) {
  std::vector<Candidate> local;
  std::set<std::string> keys;
  auto keep = [&](const Candidate& c) {
    if (sample_local(c.kind) && keys.insert(c.key()).second) local.push_back(c);
  };
  for (const auto& c : candidates(d, options)) keep(c);
  for (int j = 1; j <= d.joints; ++j)
    for (const auto& c : friction_options(d, options, j)) keep(c);
  return local;
}

// A piece of a run (between the log's gaps) and the samples it keeps: multiples of the interval
// on the log's clock, `edge` samples in from each end.
struct Piece {
  const NamedSamples* run;
  Eigen::Index begin, end;
  std::vector<Eigen::Index> keep;  // relative to begin
};

std::vector<Piece> cut_pieces(const std::vector<NamedSamples>& runs, double base, double interval, Eigen::Index edge) {
  std::vector<Piece> pieces;
  for (const auto& r : runs) {
    const auto& s = r.samples;
    if (std::abs(s.interval - base) > 1e-12)
      throw std::invalid_argument("stack_design: runs at different base periods");
    const long step = std::lround(interval / base);
    if (step < 1 || std::abs(step * base - interval) > 1e-9)
      throw std::invalid_argument("stack_design: the interval must be a multiple of the base period");
    for (Eigen::Index a = 0; a < s.q.rows();) {
      Eigen::Index b = a + 1;
      while (b < s.q.rows() && (s.piece.empty() || s.piece[b] == s.piece[a])) ++b;
      Piece pc{&r, a, b, {}};
      for (Eigen::Index k = a + edge; k < b - edge; ++k)
        if (std::lround(s.time(k) / base) % step == 0) pc.keep.push_back(k - a);
      pieces.push_back(std::move(pc));
      a = b;
    }
  }
  return pieces;
}

// The stack's matrices (and the effects' terms) sized for `rows` samples, keeping the rows they
// have: the allocation before the pieces, and the shrink when pieces were left out.
void size_stack(DesignStack& d, Eigen::Index rows, Eigen::Index p, Eigen::Index pe) {
  const Eigen::Index n = d.joints;
  d.q.conservativeResize(rows, n);
  d.qd.conservativeResize(rows, n);
  d.qdd.conservativeResize(rows, n);
  d.tau.conservativeResize(rows, n);
  d.time.conservativeResize(rows);
  d.W.conservativeResize(rows * n, p);
  d.tau0.conservativeResize(rows * n);
  d.full_extra.conservativeResize(rows * n, pe);
  for (auto& [key, m] : d.effect_terms) m.conservativeResize(rows, m.cols());
}

// What every piece is filtered with.
struct Filters {
  std::vector<preprocess::Biquad> sections, slow;  // the stack's low-pass; the effects' velocity one (may be empty)
  int padding = 0, slow_padding = 0;
};

// One piece into the stack from row `out` on: its motion through the low-pass, then joint by
// joint (memory: one joint's columns at the log's rate at a time) every regressor column, the
// fixed torque, the measured torque and the sample-local effects' terms through the same
// low-pass, kept at the piece's kept samples.
void stack_piece(const StackModel& m, const Piece& pc, const std::vector<int>& extra,
                 const std::vector<Candidate>& local, const Filters& f, Eigen::Index out, DesignStack& d) {
  const int n = m.nq, p = m.np, pf = static_cast<int>(m.full_parameters.size());
  const Eigen::Index pe = static_cast<Eigen::Index>(extra.size());
  const auto& s = pc.run->samples;
  const Eigen::Index L = pc.end - pc.begin, K = static_cast<Eigen::Index>(pc.keep.size());
  d.segment_trajectory.push_back(pc.run->name);
  const int seg = static_cast<int>(d.segment_trajectory.size()) - 1;
  // Motion signals through the same low-pass (for the sample-wise views of the stack).
  preprocess::Channels motion(L, 3 * n);
  motion.leftCols(n) = s.q.middleRows(pc.begin, L);
  motion.middleCols(n, n) = s.qd.middleRows(pc.begin, L);
  motion.rightCols(n) = s.qdd.middleRows(pc.begin, L);
  preprocess::filtfilt(f.sections, f.padding, motion);
  preprocess::Channels qd_effects = s.qd.middleRows(pc.begin, L);
  if (!f.slow.empty() && L > f.slow_padding + 1) preprocess::filtfilt(f.slow, f.slow_padding, qd_effects);
  for (Eigen::Index i = 0; i < K; ++i) {
    const Eigen::Index k = pc.keep[i];
    d.q.row(out + i) = motion.row(k).head(n);
    d.qd.row(out + i) = motion.row(k).segment(n, n);
    d.qdd.row(out + i) = motion.row(k).tail(n);
    d.time(out + i) = s.time(pc.begin + k);
    d.segment.push_back(seg);
  }
  Eigen::MatrixXd w(n, p);
  Eigen::VectorXd t0(n), q(n), qd(n), qdd(n);
  Eigen::MatrixXd wf(n, pf);
  std::vector<double> terms(64);
  for (int j = 0; j < n; ++j) {
    Eigen::Index cols = p + pe + 2;
    for (const auto& c : local)
      if (c.joint == j + 1) cols += static_cast<Eigen::Index>(c.parameters.size());
    preprocess::Channels X(L, cols);
    for (Eigen::Index k = 0; k < L; ++k) {
      const Eigen::Index g = pc.begin + k;
      q = s.q.row(g).transpose();
      qd = s.qd.row(g).transpose();
      qdd = s.qdd.row(g).transpose();
      m.regressor(q.data(), qd.data(), qdd.data(), w.data());
      m.fixed_torque(q.data(), qd.data(), qdd.data(), t0.data());
      X.row(k).head(p) = w.row(j);
      if (pe > 0) {
        m.full_regressor(q.data(), qd.data(), qdd.data(), wf.data());
        for (Eigen::Index c = 0; c < pe; ++c) X(k, p + c) = wf(j, extra[static_cast<std::size_t>(c)]);
      }
      X(k, p + pe) = t0(j);
      X(k, p + pe + 1) = s.tau(g, j);
      Eigen::Index c0 = p + pe + 2;
      for (const auto& c : local) {
        if (c.joint != j + 1) continue;
        const Eigen::Index m_c = static_cast<Eigen::Index>(c.parameters.size());
        effect_terms(c, q(j), qd_effects(k, j), terms.data());
        for (Eigen::Index i = 0; i < m_c; ++i) X(k, c0 + i) = terms[static_cast<std::size_t>(i)];
        c0 += m_c;
      }
    }
    preprocess::filtfilt(f.sections, f.padding, X);
    for (Eigen::Index i = 0; i < K; ++i) {
      const Eigen::Index k = pc.keep[i], r = (out + i) * n + j;
      d.W.row(r) = X.row(k).head(p);
      d.full_extra.row(r) = X.row(k).segment(p, pe);
      d.tau0(r) = X(k, p + pe);
      d.tau(out + i, j) = X(k, p + pe + 1);
      Eigen::Index c0 = p + pe + 2;
      for (const auto& c : local) {
        if (c.joint != j + 1) continue;
        const Eigen::Index m_c = static_cast<Eigen::Index>(c.parameters.size());
        d.effect_terms[c.key()].row(out + i) = X.row(k).segment(c0, m_c);
        c0 += m_c;
      }
    }
  }
}

}  // namespace

DesignStack stack_design(const StackModel& m, const std::vector<NamedSamples>& runs, const StackOptions& options) {
  DesignStack d;
  d.joints = m.nq;
  d.interval = options.interval;
  d.cutoff = options.cutoff;
  d.filter_order = options.order;
  const std::vector<int> extra = describe_model(m, d);
  const Eigen::Index p = m.np, pe = static_cast<Eigen::Index>(extra.size());
  const std::vector<Candidate> local = sample_local_candidates(d, options.candidates);

  const double base = runs.empty() ? 0.0 : runs.front().samples.interval;
  if (!(base > 0)) throw std::invalid_argument("stack_design: no samples");
  d.base_interval = base;
  Filters f;
  f.sections = preprocess::butterworth_lowpass(options.order, options.cutoff, 1.0 / base);
  f.padding = preprocess::zero_phase_padding(f.sections);
  if (options.effect_velocity_cutoff > 0 && options.effect_velocity_cutoff < 0.5 / base) {
    f.slow = preprocess::butterworth_lowpass(options.order, options.effect_velocity_cutoff, 1.0 / base);
    f.slow_padding = preprocess::zero_phase_padding(f.slow);
  }
  // 6 filter time constants (by default) cut at each piece's ends: the filter's edge transients.
  const Eigen::Index edge =
      static_cast<Eigen::Index>(std::ceil(options.edge_time_constants * preprocess::slowest_time_constant(f.sections)));
  const std::vector<Piece> pieces = cut_pieces(runs, base, options.interval, edge);
  Eigen::Index total = 0;
  for (const auto& pc : pieces) total += static_cast<Eigen::Index>(pc.keep.size());

  size_stack(d, total, p, pe);
  for (const auto& c : local)
    d.effect_terms[c.key()] = Eigen::MatrixXd(total, static_cast<Eigen::Index>(c.parameters.size()));
  Eigen::Index out = 0;
  for (const auto& pc : pieces) {
    const Eigen::Index L = pc.end - pc.begin, K = static_cast<Eigen::Index>(pc.keep.size());
    if (L <= f.padding + 1 || K == 0) continue;  // too short to filter: left out
    stack_piece(m, pc, extra, local, f, out, d);
    out += K;
  }
  if (out < total) size_stack(d, out, p, pe);  // pieces left out shrink the stack
  return d;
}

}  // namespace symoro::diagnose
