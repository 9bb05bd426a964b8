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

DesignStack stack_design(const StackModel& m, const std::vector<NamedSamples>& runs, const StackOptions& options) {
  const int n = m.nq, p = m.np, pf = static_cast<int>(m.full_parameters.size());
  DesignStack d;
  d.joints = n;
  d.interval = options.interval;
  d.cutoff = options.cutoff;
  d.filter_order = options.order;
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
  const Eigen::Index pe = static_cast<Eigen::Index>(extra.size());
  // The sample-local candidates, and the friction a named joint's is chosen from again
  // (friction_smoothing.hpp), each once.
  std::vector<Candidate> local;
  std::set<std::string> keys;
  auto keep = [&](const Candidate& c) {
    if (sample_local(c.kind) && keys.insert(c.key()).second) local.push_back(c);
  };
  for (const auto& c : candidates(d, options.candidates)) keep(c);
  for (int j = 1; j <= n; ++j)
    for (const auto& c : friction_options(d, options.candidates, j)) keep(c);

  // The pieces and the samples each keeps (multiples of the interval on the log's clock).
  struct Piece {
    const NamedSamples* run;
    Eigen::Index begin, end;
    std::vector<Eigen::Index> keep;  // relative to begin
  };
  std::vector<Piece> pieces;
  Eigen::Index total = 0;
  double base = runs.empty() ? 0.0 : runs.front().samples.interval;
  if (!(base > 0)) throw std::invalid_argument("stack_design: no samples");
  d.base_interval = base;
  const auto sections = preprocess::butterworth_lowpass(options.order, options.cutoff, 1.0 / base);
  const int padding = preprocess::zero_phase_padding(sections);
  std::vector<preprocess::Biquad> slow;
  int slow_padding = 0;
  if (options.effect_velocity_cutoff > 0 && options.effect_velocity_cutoff < 0.5 / base) {
    slow = preprocess::butterworth_lowpass(options.order, options.effect_velocity_cutoff, 1.0 / base);
    slow_padding = preprocess::zero_phase_padding(slow);
  }
  const Eigen::Index edge =
      static_cast<Eigen::Index>(std::ceil(options.edge_time_constants * preprocess::slowest_time_constant(sections)));
  for (const auto& r : runs) {
    const auto& s = r.samples;
    if (std::abs(s.interval - base) > 1e-12) throw std::invalid_argument("stack_design: runs at different base periods");
    const long step = std::lround(options.interval / base);
    if (step < 1 || std::abs(step * base - options.interval) > 1e-9)
      throw std::invalid_argument("stack_design: the interval must be a multiple of the base period");
    for (Eigen::Index a = 0; a < s.q.rows();) {
      Eigen::Index b = a + 1;
      while (b < s.q.rows() && (s.piece.empty() || s.piece[b] == s.piece[a])) ++b;
      Piece pc{&r, a, b, {}};
      for (Eigen::Index k = a + edge; k < b - edge; ++k)
        if (std::lround(s.time(k) / base) % step == 0) pc.keep.push_back(k - a);
      total += static_cast<Eigen::Index>(pc.keep.size());
      pieces.push_back(std::move(pc));
      a = b;
    }
  }

  d.q.resize(total, n);
  d.qd.resize(total, n);
  d.qdd.resize(total, n);
  d.tau.resize(total, n);
  d.time.resize(total);
  d.W.resize(total * n, p);
  d.tau0.resize(total * n);
  d.full_extra.resize(total * n, pe);
  std::vector<Eigen::Index> local_cols;
  for (const auto& c : local) {
    d.effect_terms[c.key()] = Eigen::MatrixXd(total, static_cast<Eigen::Index>(c.parameters.size()));
    local_cols.push_back(static_cast<Eigen::Index>(c.parameters.size()));
  }

  Eigen::MatrixXd w(n, p);
  Eigen::VectorXd t0(n), q(n), qd(n), qdd(n);
  Eigen::MatrixXd wf(n, pf);
  std::vector<double> terms(64);
  Eigen::Index out = 0;
  for (const auto& pc : pieces) {
    const auto& s = pc.run->samples;
    const Eigen::Index L = pc.end - pc.begin, K = static_cast<Eigen::Index>(pc.keep.size());
    if (L <= padding + 1 || K == 0) continue;  // too short to filter: left out
    d.segment_trajectory.push_back(pc.run->name);
    const int seg = static_cast<int>(d.segment_trajectory.size()) - 1;
    // Motion signals through the same low-pass (for the sample-wise views of the stack).
    preprocess::Channels motion(L, 3 * n);
    motion.leftCols(n) = s.q.middleRows(pc.begin, L);
    motion.middleCols(n, n) = s.qd.middleRows(pc.begin, L);
    motion.rightCols(n) = s.qdd.middleRows(pc.begin, L);
    preprocess::filtfilt(sections, padding, motion);
    preprocess::Channels qd_effects = s.qd.middleRows(pc.begin, L);
    if (!slow.empty() && L > slow_padding + 1) preprocess::filtfilt(slow, slow_padding, qd_effects);
    for (Eigen::Index i = 0; i < K; ++i) {
      const Eigen::Index k = pc.keep[i];
      d.q.row(out + i) = motion.row(k).head(n);
      d.qd.row(out + i) = motion.row(k).segment(n, n);
      d.qdd.row(out + i) = motion.row(k).tail(n);
      d.time(out + i) = s.time(pc.begin + k);
      d.segment.push_back(seg);
    }
    // Joint by joint (memory: one joint's columns at the log's rate at a time).
    for (int j = 0; j < n; ++j) {
      Eigen::Index cols = p + pe + 2;
      for (std::size_t c = 0; c < local.size(); ++c)
        if (local[c].joint == j + 1) cols += local_cols[c];
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
        for (std::size_t c = 0; c < local.size(); ++c) {
          if (local[c].joint != j + 1) continue;
          effect_terms(local[c], q(j), qd_effects(k, j), terms.data());
          for (Eigen::Index i = 0; i < local_cols[c]; ++i) X(k, c0 + i) = terms[static_cast<std::size_t>(i)];
          c0 += local_cols[c];
        }
      }
      preprocess::filtfilt(sections, padding, X);
      for (Eigen::Index i = 0; i < K; ++i) {
        const Eigen::Index k = pc.keep[i], r = (out + i) * n + j;
        d.W.row(r) = X.row(k).head(p);
        d.full_extra.row(r) = X.row(k).segment(p, pe);
        d.tau0(r) = X(k, p + pe);
        d.tau(out + i, j) = X(k, p + pe + 1);
        Eigen::Index c0 = p + pe + 2;
        for (std::size_t c = 0; c < local.size(); ++c) {
          if (local[c].joint != j + 1) continue;
          d.effect_terms[local[c].key()].row(out + i) = X.row(k).segment(c0, local_cols[c]);
          c0 += local_cols[c];
        }
      }
    }
    out += K;
  }
  // Pieces left out shrink the stack.
  if (out < total) {
    d.q.conservativeResize(out, n);
    d.qd.conservativeResize(out, n);
    d.qdd.conservativeResize(out, n);
    d.tau.conservativeResize(out, n);
    d.time.conservativeResize(out);
    d.W.conservativeResize(out * n, p);
    d.tau0.conservativeResize(out * n);
    d.full_extra.conservativeResize(out * n, pe);
    for (auto& [key, m] : d.effect_terms) m.conservativeResize(out, m.cols());
  }
  return d;
}

}  // namespace symoro::diagnose
