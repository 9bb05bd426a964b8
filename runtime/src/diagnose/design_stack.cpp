#include "symoro/diagnose/design_stack.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::diagnose {

Eigen::VectorXd DesignStack::target() const { return stacked(tau) - tau0; }

void DesignStack::hold(const Eigen::VectorXd& phi) {
  if (held()) throw std::logic_error("DesignStack::hold: parameters are already held");
  if (phi.size() != W.cols())
    throw std::invalid_argument("DesignStack::hold: " + std::to_string(phi.size()) + " parameters for a model with " +
                                std::to_string(W.cols()));
  tau0 += W * phi;
  held_phi = phi;
}

Eigen::VectorXd DesignStack::stacked(const Eigen::MatrixXd& m) const {
  Eigen::VectorXd v(m.rows() * m.cols());
  for (Eigen::Index s = 0; s < m.rows(); ++s) v.segment(s * m.cols(), m.cols()) = m.row(s).transpose();
  return v;
}

Eigen::MatrixXd DesignStack::rate(const Eigen::MatrixXd& x) const {
  const Eigen::Index S = x.rows();
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(S, x.cols());
  for (Eigen::Index s = 0; s < S; ++s) {
    const bool prev = s > 0 && segment[s - 1] == segment[s];
    const bool next = s + 1 < S && segment[s + 1] == segment[s];
    if (prev && next)
      r.row(s) = (x.row(s + 1) - x.row(s - 1)) / (2 * interval);
    else if (next)
      r.row(s) = (x.row(s + 1) - x.row(s)) / interval;
    else if (prev)
      r.row(s) = (x.row(s) - x.row(s - 1)) / interval;
  }
  return r;
}

DesignStack::Filtered DesignStack::filtered(const Eigen::MatrixXd& x, const std::function<double(double)>& f) const {
  const Eigen::Index S = x.rows(), C = x.cols();
  Filtered out;
  if (!(base_interval > 0 && cutoff > 0 && filter_order > 0)) {
    out.value = x.unaryExpr(f);
    out.rate = rate(out.value);
    out.accel = rate(out.rate);
    return out;
  }
  out.value = out.rate = out.accel = Eigen::MatrixXd::Zero(S, C);
  const auto sections = preprocess::butterworth_lowpass(filter_order, cutoff, 1.0 / base_interval);
  const int padding = preprocess::zero_phase_padding(sections);
  const double h = base_interval;
  for (Eigen::Index a = 0; a < S;) {
    Eigen::Index b = a + 1;
    while (b < S && segment[b] == segment[a]) ++b;
    // Fine sample of each grid sample, by its time within the trajectory.
    std::vector<Eigen::Index> at(static_cast<std::size_t>(b - a));
    for (Eigen::Index s = a; s < b; ++s) at[s - a] = std::lround((time(s) - time(a)) / h);
    const Eigen::Index L = at.back() + 1;
    preprocess::Channels y(L, C);
    for (Eigen::Index s = a; s + 1 < b; ++s) {
      const Eigen::Index k0 = at[s - a], k1 = at[s + 1 - a];
      for (Eigen::Index k = k0; k < k1; ++k) {
        const double u = static_cast<double>(k - k0) / static_cast<double>(k1 - k0);
        for (Eigen::Index c = 0; c < C; ++c) y(k, c) = f((1 - u) * x(s, c) + u * x(s + 1, c));
      }
    }
    for (Eigen::Index c = 0; c < C; ++c) y(L - 1, c) = f(x(b - 1, c));
    if (L > padding + 1) preprocess::filtfilt(sections, padding, y);
    auto d1 = [&](Eigen::Index k, Eigen::Index c) {
      if (L < 2) return 0.0;
      if (k == 0) return (y(1, c) - y(0, c)) / h;
      if (k == L - 1) return (y(k, c) - y(k - 1, c)) / h;
      return (y(k + 1, c) - y(k - 1, c)) / (2 * h);
    };
    auto d2 = [&](Eigen::Index k, Eigen::Index c) {
      if (L < 3) return 0.0;
      k = std::min(std::max<Eigen::Index>(k, 1), L - 2);
      return (y(k + 1, c) - 2 * y(k, c) + y(k - 1, c)) / (h * h);
    };
    for (Eigen::Index s = a; s < b; ++s)
      for (Eigen::Index c = 0; c < C; ++c) {
        const Eigen::Index k = at[s - a];
        out.value(s, c) = y(k, c);
        out.rate(s, c) = d1(k, c);
        out.accel(s, c) = d2(k, c);
      }
    a = b;
  }
  return out;
}

}  // namespace symoro::diagnose
