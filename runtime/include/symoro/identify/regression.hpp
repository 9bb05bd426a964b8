// The stacked IDIM regression of one run (paper eq. stacked_regression): every target-grid
// sample's regressor W(q, qd, qdd) stacked sample after sample, and the measured torque minus
// the torque of the model's fixed parameters, so that y = W phi + e.
#pragma once

#include <Eigen/Core>

#include "symoro/preprocess/preprocess.hpp"

namespace symoro::identify {

struct Regression {
  Eigen::MatrixXd W;  // (samples * joints) x parameters; row s * joints + j
  Eigen::VectorXd y;  // measured tau minus fixed_torque, same rows
  int joints = 0, samples = 0;
};

template <class Model>
Regression stack_regression(const preprocess::Samples& s) {
  constexpr int n = Model::nq, p = Model::np;
  Regression r;
  r.joints = n;
  r.samples = static_cast<int>(s.q.rows());
  r.W.resize(static_cast<Eigen::Index>(r.samples) * n, p);
  r.y.resize(static_cast<Eigen::Index>(r.samples) * n);
  Eigen::Matrix<double, n, p> w;
  Eigen::Matrix<double, n, 1> tau0;
  for (int k = 0; k < r.samples; ++k) {
    const Eigen::Matrix<double, n, 1> q = s.q.row(k).transpose(), qd = s.qd.row(k).transpose(),
                                      qdd = s.qdd.row(k).transpose();
    Model::regressor(q, qd, qdd, w);
    Model::fixed_torque(q, qd, qdd, tau0);
    r.W.middleRows(static_cast<Eigen::Index>(k) * n, n) = w;
    r.y.segment(static_cast<Eigen::Index>(k) * n, n) = s.tau.row(k).transpose() - tau0;
  }
  return r;
}

}  // namespace symoro::identify
