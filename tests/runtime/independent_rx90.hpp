// The RX-90 as an independent arm (independent_arm.hpp) runs it: a twin description built from
// the model's frames with random physical links, and smooth excitations from its joint ranges.
// Shared by the tests that synthesize RX-90 logs apart from the project's twin.
#pragma once

#include <cmath>
#include <string>

#include <fmt/format.h>
#include <symoro/rx90.hpp>

#include <Eigen/Geometry>

#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "test_support.hpp"

namespace symoro::test {

// The model's frames as a URDF chain (joint origin RotX(alpha) TransX(d) RotZ(theta) TransZ(r),
// axis z), random physical links on them, industrial drives and servos, and FF+PD gains from
// the inertia at the start posture.
inline twin::TwinConfig rx90_twin() {
  constexpr int n = rx90::Model::nq;
  twin::TwinConfig c;
  c.path = "test twin of the RX-90";
  test::Random rng(7);
  for (int j = 0; j < n; ++j) {
    const FrameInfo& f = rx90::Model::frames[j];
    twin::UrdfJoint J;
    J.name = fmt::format("joint{}", j + 1);
    J.model_joint = j + 1;
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(f.alpha, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(f.theta, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    J.xyz =
        Eigen::Vector3d(f.d, 0, 0) + Eigen::AngleAxisd(f.alpha, Eigen::Vector3d::UnitX()) * Eigen::Vector3d(0, 0, f.r);
    const Eigen::Vector3d ypr = R.eulerAngles(2, 1, 0);
    J.rpy = Eigen::Vector3d(ypr(2), ypr(1), ypr(0));
    c.chain.joints.push_back(J);
    const test::LinkInertia L = test::random_physical_link(rng);
    twin::UrdfInertial I;
    I.name = fmt::format("link{}", j + 1);
    I.on = J.name;
    I.mass = L.m;
    I.com = L.ms / L.m;
    I.inertia = L.J - L.m * (I.com.squaredNorm() * Eigen::Matrix3d::Identity() - I.com * I.com.transpose());
    c.chain.inertials.push_back(I);
  }
  c.rotor_inertia.resize(n);
  c.rotor_inertia << 0.4, 0.4, 0.2, 0.04, 0.04, 0.02;
  c.viscous.resize(n);
  c.viscous << 2.0, 2.0, 1.0, 0.3, 0.3, 0.2;
  for (int j = 0; j < n; ++j) c.servos.push_back({"industrial", 1.0, 0.002, rx90::Model::joints[j].effort, 1 << 18});
  c.effects.disable_all();
  c.effects.backlash_width = Eigen::VectorXd::Zero(n);
  const auto phi = twin::make_truth(symoro::robot::compiled_model<rx90::Model>(), c).phi;
  Eigen::Matrix<double, n, n> M;
  rx90::Model::inertia(Eigen::Matrix<double, n, 1>::Zero(), phi, M);
  c.controller.realization_inertia = M.diagonal();
  c.controller.realization_damping = c.viscous;
  c.controller.bandwidth = Eigen::VectorXd::Constant(n, 30);
  c.controller.damping_ratio = Eigen::VectorXd::Ones(n);
  return c;
}

// Three cosines per joint from the middle of its range (up to a third of the half range each),
// starting at rest, as a controller's own excitation would be.
inline trajectory::SampledReference rx90_reference(const std::string& name, double seconds, unsigned seed) {
  constexpr int n = rx90::Model::nq;
  test::Random rng(seed);
  trajectory::SampledReference ref;
  ref.name = name;
  ref.period = 0.001;
  const int K = static_cast<int>(seconds / ref.period) + 1;
  ref.q = ref.qd = ref.qdd = Eigen::MatrixXd::Zero(n, K);
  for (int j = 0; j < n; ++j) {
    const auto& J = rx90::Model::joints[j];
    const double mid = 0.5 * (J.lower + J.upper), half = 0.5 * (J.upper - J.lower);
    for (int w = 0; w < 3; ++w) {
      const double a = half / 3 / 2 * rng.uniform(0.6, 1.0) * (rng.uniform(0, 1) < 0.5 ? -1 : 1);
      const double f = 2 * M_PI * rng.uniform(0.1, 0.4);
      for (int k = 0; k < K; ++k) {
        const double t = k * ref.period;
        ref.q(j, k) += a * (1 - std::cos(f * t));
        ref.qd(j, k) += a * f * std::sin(f * t);
        ref.qdd(j, k) += a * f * f * std::cos(f * t);
      }
    }
    ref.q.row(j).array() += mid;
  }
  return ref;
}

}  // namespace symoro::test
