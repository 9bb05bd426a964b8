#include "symoro/diagnose/design_stack.hpp"

namespace symoro::diagnose {

Eigen::VectorXd DesignStack::target() const { return stacked(tau) - tau0; }

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

}  // namespace symoro::diagnose
