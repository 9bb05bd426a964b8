// The C++ side of test_models.py's bit-for-bit comparison: random states of three models, and
// every generated function's result on them, called the way a C++ user calls them (the
// returning overloads, Eigen's own column-major types). Written as raw little-endian float64
// in C order, one file per quantity: <dir>/<robot>.<model>.<quantity>.bin.
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include <Eigen/Core>

#include <symoro/crane_x7.hpp>
#include <symoro/planar2r.hpp>
#include <symoro/rx90.hpp>

namespace {

constexpr int kStates = 6;

template <class M>
void put(std::ofstream& out, const Eigen::MatrixBase<M>& m) {
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      const double v = m(i, j);
      out.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
}

struct Files {
  std::string prefix;
  std::ofstream open(const std::string& quantity) const {
    return std::ofstream(prefix + quantity + ".bin", std::ios::binary);
  }
};

template <class Model>
void write_model(const std::string& dir, const std::string& name, std::uint64_t seed) {
  constexpr int nq = Model::nq, np = Model::np, ns = Model::ns;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  // Plausible standard parameters (positive masses and inertias, small first moments), so that
  // M(q; phi) is positive definite and the forward dynamics well defined.
  Eigen::Matrix<double, ns, 1> s;
  for (int i = 0; i < ns; ++i) {
    const std::string f = Model::standard_parameters[i].family;
    const double r = u(rng);
    s[i] = f == "XX" || f == "YY" || f == "ZZ"   ? 0.6 + 0.3 * r
           : f == "M"                            ? 1.5 + 0.5 * r
           : f == "IA" || f == "FV" || f == "FS" ? 0.05 + 0.04 * r
           : f == "MX" || f == "MY" || f == "MZ" ? 0.1 * r
                                                 : 0.01 * r;
  }
  const Eigen::Matrix<double, np, 1> phi = Model::base_from_standard(s);
  const Files f{dir + "/" + name + "."};
  auto in_q = f.open("q"), in_qd = f.open("qd"), in_qdd = f.open("qdd"), in_tau = f.open("tau_in"),
       in_phi = f.open("phi"), in_s = f.open("s");
  auto w = f.open("regressor"), id = f.open("inverse_dynamics"), mm = f.open("inertia"),
       h = f.open("nonlinear_effects"), fd = f.open("forward_dynamics"), idd_tau = f.open("idd_tau"),
       idd_dq = f.open("idd_dq"), idd_dqd = f.open("idd_dqd"), fdd_qdd = f.open("fdd_qdd"), fdd_dq = f.open("fdd_dq"),
       fdd_dqd = f.open("fdd_dqd"), fdd_dtau = f.open("fdd_dtau"), fdd_dphi = f.open("fdd_dphi"),
       fdd_pivot = f.open("fdd_min_pivot"), fk = f.open("forward_kinematics"), jac = f.open("jacobian"),
       bfs = f.open("base_from_standard");
  put(in_phi, phi.transpose());
  put(in_s, s.transpose());
  put(bfs, phi.transpose());
  for (int k = 0; k < kStates; ++k) {
    Eigen::Matrix<double, nq, 1> q, qd, qdd, tau;
    for (int j = 0; j < nq; ++j) {
      const auto& joint = Model::joints[j];
      q[j] = 0.5 * (joint.lower + joint.upper) + 0.4 * (joint.upper - joint.lower) * u(rng);
      qd[j] = 2 * u(rng);
      qdd[j] = 5 * u(rng);
      tau[j] = 3 * u(rng);
    }
    put(in_q, q.transpose());
    put(in_qd, qd.transpose());
    put(in_qdd, qdd.transpose());
    put(in_tau, tau.transpose());
    put(w, Model::regressor(q, qd, qdd));
    put(id, Model::inverse_dynamics(q, qd, qdd, phi).transpose());
    put(mm, Model::inertia(q, phi));
    put(h, Model::nonlinear_effects(q, qd, phi).transpose());
    put(fd, Model::forward_dynamics(q, qd, tau, phi).transpose());
    typename Model::template InverseDynamicsDerivatives<double> di;
    Model::inverse_dynamics_derivatives(q, qd, qdd, phi, di);
    put(idd_tau, di.tau.transpose());
    put(idd_dq, di.dq);
    put(idd_dqd, di.dqd);
    typename Model::template ForwardDynamicsDerivatives<double> df;
    if (!Model::forward_dynamics_derivatives(q, qd, tau, phi, df)) {
      std::fprintf(stderr, "%s: M not positive definite at state %d\n", name.c_str(), k);
      std::exit(1);
    }
    put(fdd_qdd, df.qdd.transpose());
    put(fdd_dq, df.dq);
    put(fdd_dqd, df.dqd);
    put(fdd_dtau, df.dtau);
    put(fdd_dphi, df.dphi);
    put(fdd_pivot, Eigen::Matrix<double, 1, 1>::Constant(df.min_pivot));
    put(fk, Model::forward_kinematics(q));
    put(jac, Model::jacobian(q));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: python_model_reference <dir>\n");
    return 2;
  }
  const std::string dir = argv[1];
  write_model<symoro::planar2r::Model>(dir, "planar2r.full", 1);
  write_model<symoro::crane_x7::reduced::Model>(dir, "crane_x7.reduced", 2);
  write_model<symoro::rx90::Model>(dir, "rx90.full", 3);
  std::printf("%d states of planar2r.full, crane_x7.reduced, rx90.full\n", kStates);
  return 0;
}
