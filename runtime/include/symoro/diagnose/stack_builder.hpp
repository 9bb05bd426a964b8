// Builds a DesignStack from logs preprocessed at their own rate, by parallel filtering
// (Gautier): every regressor column (identified model, full model, candidate effects) and the
// torque are computed sample by sample from lightly filtered q, qd, qdd, then all pass through
// the same zero-phase low-pass and are decimated to the diagnosis grid. Since the low-pass is
// linear, y = W phi holds after it exactly as before it; filtering q first and evaluating the
// nonlinear model on it afterwards does not (gravity and inertia are nonlinear in q), which
// leaves a residual on the loaded joints that looks like a missing effect.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/diagnose/design_stack.hpp"
#include "symoro/diagnose/effects.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::diagnose {

struct NamedSamples {
  std::string name;
  preprocess::Samples samples;  // at the log's base period, lightly filtered (light_preprocessing)
};

struct StackOptions {
  double interval = 0.01;  // s, the diagnosis grid
  double cutoff = 5.0;     // Hz, the low-pass on every column and the torque
  int order = 4;
  // Samples this many of the low-pass's slowest time constants from either end of a piece are
  // left out: the zero-phase filter's end extension is not the signal (a torque spike in a
  // log's first row spreads over ~5 time constants).
  double edge_time_constants = 6;
  // The candidate effects' own terms (friction: sign-like in qd) take qd low-passed to this
  // cutoff: noise in qd smooths a sign by its own spread, and the wide band the regressor
  // needs (light_preprocessing) carries ~0.1 rad/s of quantization noise, more than the
  // friction's velocity scales. 0: the samples' qd as given.
  double effect_velocity_cutoff = 20.0;  // Hz
  CandidateOptions candidates;
};

// The light preprocessing the builder expects: the base period, a cutoff only to tame the
// derivatives of quantized positions, and above the drives' vibration modes (gear mesh,
// ~100 Hz). The regressor is nonlinear in qd: vibration removed before it (a 20 Hz cutoff
// did) is missing from its Coriolis and centrifugal terms, while the torque keeps their
// rectified part, which then passes the diagnosis low-pass as a slow misfit on the loaded
// joints (a spurious offset on joint 2 with a 4 ms delay or with backlash on the twin).
// The derivative noise it lets in is averaged by the low-pass where it enters linearly; its
// square biases the velocity-squared terms by well under a mN m at 4096 counts/rev.
inline preprocess::Options light_preprocessing(double cutoff_hz = 150.0) {
  preprocess::Options o;
  o.derivative_cutoff = cutoff_hz;
  return o;
}

template <class Full, class Identified>
DesignStack stack_design(const std::vector<NamedSamples>& runs, const StackOptions& o = {}) {
  constexpr int n = Identified::nq, p = Identified::np, pf = Full::np;
  static_assert(Full::nq == n, "the full and identified models must have the same joints");
  DesignStack d;
  d.joints = n;
  d.interval = o.interval;
  d.cutoff = o.cutoff;
  d.filter_order = o.order;
  for (const auto& j : Identified::joints) d.joint_names.push_back(j.name);
  for (const auto& par : Identified::parameters) d.parameters.push_back(par.name);
  d.rotor_inertia_index = Eigen::VectorXd::Constant(n, -1);
  d.viscous_index = Eigen::VectorXd::Constant(n, -1);
  for (int i = 0; i < p; ++i) {
    const auto& par = Identified::parameters[i];
    const std::string fam = par.family;
    if (par.joint >= 1 && par.joint <= n && fam == "IA") d.rotor_inertia_index(par.joint - 1) = i;
    if (par.joint >= 1 && par.joint <= n && fam == "FV") d.viscous_index(par.joint - 1) = i;
  }
  // The payload's base parameters per unit of the last massive link's M, MX, MY, MZ.
  for (const auto& par : Identified::standard_parameters)
    if (std::string(par.family) == "M") d.payload_link = std::max(d.payload_link, par.joint);
  if (d.payload_link > 0) {
    const std::string families[] = {"M", "MX", "MY", "MZ"};
    d.payload_map = Eigen::MatrixXd::Zero(p, 4);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < Identified::ns; ++k) {
        const auto& par = Identified::standard_parameters[k];
        if (par.joint != d.payload_link || families[c] != par.family) continue;
        Eigen::Matrix<double, Identified::ns, 1> unit = Eigen::Matrix<double, Identified::ns, 1>::Zero();
        unit(k) = 1;
        d.payload_map.col(c) = Identified::base_from_standard(unit);
      }
  }
  std::vector<int> extra;
  for (int i = 0; i < pf; ++i) {
    bool identified = false;
    for (const auto& par : Identified::parameters) identified |= std::string(par.name) == Full::parameters[i].name;
    if (identified) continue;
    extra.push_back(i);
    d.full_extra_names.push_back(Full::parameters[i].name);
    d.full_extra_families.push_back(Full::parameters[i].family);
    d.full_extra_joints.push_back(Full::parameters[i].joint);
  }
  const Eigen::Index pe = static_cast<Eigen::Index>(extra.size());
  std::vector<Candidate> local;
  for (const auto& c : candidates(d, o.candidates))
    if (sample_local(c.kind)) local.push_back(c);

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
  const auto sections = preprocess::butterworth_lowpass(o.order, o.cutoff, 1.0 / base);
  const int padding = preprocess::zero_phase_padding(sections);
  std::vector<preprocess::Biquad> slow;
  int slow_padding = 0;
  if (o.effect_velocity_cutoff > 0 && o.effect_velocity_cutoff < 0.5 / base) {
    slow = preprocess::butterworth_lowpass(o.order, o.effect_velocity_cutoff, 1.0 / base);
    slow_padding = preprocess::zero_phase_padding(slow);
  }
  const Eigen::Index edge =
      static_cast<Eigen::Index>(std::ceil(o.edge_time_constants * preprocess::slowest_time_constant(sections)));
  for (const auto& r : runs) {
    const auto& s = r.samples;
    if (std::abs(s.interval - base) > 1e-12) throw std::invalid_argument("stack_design: runs at different base periods");
    const long step = std::lround(o.interval / base);
    if (step < 1 || std::abs(step * base - o.interval) > 1e-9)
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

  Eigen::Matrix<double, n, p> w;
  Eigen::Matrix<double, n, 1> t0, q, qd, qdd;
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
        Identified::regressor(q, qd, qdd, w);
        Identified::fixed_torque(q, qd, qdd, t0);
        X.row(k).head(p) = w.row(j);
        if (pe > 0) {
          Full::regressor(q, qd, qdd, wf);
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
