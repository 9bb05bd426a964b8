// The closed-loop simulation and CLIE: the in-loop controller against control::FfpdController,
// the forward sensitivities against central finite differences of the simulation, the timing
// (sample-and-hold, delay, pre-roll) against the digital twin, CLIE's recovery of known
// parameters from data it could have produced, and divergence reported instead of thrown.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>

#include "symoro/control/ffpd.hpp"
#include "symoro/identify/clie.hpp"
#include "symoro/identify/clie_model.hpp"
#include "symoro/identify/closed_loop.hpp"
#include "symoro/identify/closed_loop_model.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/preprocess/zero_phase.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/random.hpp"
#include "symoro/twin/simulator.hpp"

namespace {

using namespace symoro;
using Full = crane_x7::Model;
using Reduced = crane_x7::reduced::Model;
using identify::ClosedLoopSimulator;
using preprocess::Channels;
constexpr int n = Full::nq;
const std::string kRobot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";

twin::TwinConfig ideal_config() {
  twin::TwinConfig c = twin::read_twin_config(kRobot + "/twin.yaml", n);
  c.effects.disable_all();
  return c;
}

// The first two waypoints of V01 (every joint moves, 6.1 s): short enough for finite
// differences and repeated CLIE solves.
const trajectory::Trajectory& short_trajectory() {
  static const trajectory::Trajectory t = [] {
    const auto design = trajectory::TrajectoryDesign::read(
        kRobot + "/trajectories.yaml", std::vector<JointInfo>(Full::joints.begin(), Full::joints.end()));
    trajectory::Trajectory v = design.build("V01");
    trajectory::Trajectory cut = v;
    cut.name = "V01-excerpt";
    cut.segments.clear();
    for (const auto& s : v.segments)
      if (s.end() <= 6.2) cut.segments.push_back(s);
    return cut;
  }();
  return t;
}

Eigen::VectorXd full_truth() { return twin::make_truth<Full>(ideal_config()).phi; }
Eigen::VectorXd reduced_truth() { return Reduced::from_parent(full_truth()); }

int index_of(const char* name) {
  for (int i = 0; i < Reduced::np; ++i)
    if (std::string(Reduced::parameters[i].name) == name) return i;
  ADD_FAILURE() << "no parameter " << name;
  return 0;
}

double rms(const Eigen::MatrixXd& a) { return std::sqrt(a.squaredNorm() / static_cast<double>(a.size())); }

// The zero-phase low-pass preprocessing applies for `interval` samples, on the 1 kHz grid.
Channels lowpassed(Channels x, double interval) {
  const preprocess::Options o;
  const double cutoff = std::min(o.derivative_cutoff, o.anti_alias_fraction * 0.5 / interval);
  const auto sections = preprocess::butterworth_lowpass(o.filter_order, cutoff, 1 / 0.001);  // the twin's 1 kHz
  preprocess::filtfilt(sections, preprocess::zero_phase_padding(sections), x);
  return x;
}

TEST(ClosedLoopController, SensitivityFormMatchesFfpdControllerAndIsItsDerivative) {
  const identify::ClosedLoopSetup setup = identify::closed_loop_setup(ideal_config());
  control::FfpdController reference(setup.gains);
  identify::detail::FfpdSensitivity<n, 3> loop(setup.gains);
  identify::detail::FfpdSensitivity<n, 3> moved(setup.gains);
  twin::Random rng(7);
  using Vec = Eigen::Matrix<double, n, 1>;
  using Sens = Eigen::Matrix<double, n, 3>;
  auto random_vec = [&](double scale) {
    Vec v;
    for (int j = 0; j < n; ++j) v(j) = scale * rng.normal();
    return v;
  };
  Vec q = random_vec(0.5);
  reference.reset(q);
  loop.reset<true>(q);
  moved.reset<false>(q);
  // q_k(phi) = q_k + S_k phi is affine, so u_k(phi) is too: d u . delta is exact.
  const Eigen::Vector3d delta(1e-3, -2e-3, 5e-4);
  double worst_u = 0, worst_du = 0;
  for (int k = 0; k < 200; ++k) {
    q += random_vec(0.01);
    const Sens dq = Sens::Random();
    const Vec qr = random_vec(0.5), qdr = random_vec(1), qddr = random_vec(3);
    Vec u, u_moved;
    Sens du, unused;
    loop.update<true>(q, dq, qr, qdr, qddr, u, du);
    moved.update<false>(q + dq * delta, unused, qr, qdr, qddr, u_moved, unused);
    const Eigen::VectorXd u_ref = reference.update(q, qr, qdr, qddr);
    worst_u = std::max(worst_u, (u - u_ref).cwiseAbs().maxCoeff() / (1 + u_ref.cwiseAbs().maxCoeff()));
    worst_du = std::max(worst_du, (u_moved - u - du * delta).cwiseAbs().maxCoeff());
    ASSERT_LT((loop.velocity() - reference.velocity()).cwiseAbs().maxCoeff(), 1e-12);
  }
  EXPECT_LT(worst_u, 1e-12);
  EXPECT_LT(worst_du, 1e-9);  // rounding of u ~ 10 N m
}

// The recorded torque is FfpdController's output one cycle earlier, fed the simulated q.
TEST(ClosedLoopSimulator, RecordedTorqueIsFfpdControllerOnTheSampledQ) {
  identify::ClosedLoopSetup setup = identify::closed_loop_setup(ideal_config(), 0.0);
  const ClosedLoopSimulator<Reduced> sim(setup, short_trajectory());
  Channels tau, q;
  ASSERT_TRUE(sim.simulate(reduced_truth(), tau, nullptr, nullptr, &q));
  ASSERT_EQ(tau.rows(), sim.cycles());
  EXPECT_EQ(tau.row(0).cwiseAbs().maxCoeff(), 0.0);  // no command before the first cycle
  control::FfpdController ctrl(setup.gains);
  ctrl.reset(q.row(0).transpose());
  Eigen::VectorXd qr(n), qdr(n), qddr(n);
  double worst = 0;
  for (int k = 0; k + 1 < sim.cycles(); ++k) {
    short_trajectory().evaluate(k * sim.period(), qr, qdr, qddr);
    const Eigen::VectorXd u = ctrl.update(q.row(k).transpose(), qr, qdr, qddr);
    worst = std::max(worst, (u - tau.row(k + 1).transpose()).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-12);
}

// d tau / d phi against central differences of the simulation itself, for both step layouts.
void check_sensitivities(const identify::ClosedLoopSetup& setup) {
  const ClosedLoopSimulator<Reduced> sim(setup, short_trajectory());
  const Eigen::VectorXd phi = reduced_truth();
  Channels tau, dtau, plus, minus;
  ASSERT_TRUE(sim.simulate(phi, tau, &dtau, nullptr));
  ASSERT_EQ(dtau.cols(), n * Reduced::np);
  for (const char* name : {"ZZR1", "XXR2", "MX2", "MYR3", "ZZR4", "MX5", "ZZ7", "IA4", "IA8", "FV2", "FV6"}) {
    const int i = index_of(name);
    double scale = 0;
    for (int j = 0; j < n; ++j) scale = std::max(scale, dtau.col(j * Reduced::np + i).cwiseAbs().maxCoeff());
    // A step moving tau by ~1e-4 N m: far above the loop's rounding noise, small enough that
    // the h^2 term stays near 1e-8 relative (measured: the error is ~1e-8 from h = 1e-5 / scale
    // to 1e-3 / scale, growing as h^2 above and as 1/h below).
    const double h = 1e-4 / scale;
    Eigen::VectorXd p = phi;
    p(i) += h;
    ASSERT_TRUE(sim.simulate(p, plus, nullptr, nullptr));
    p(i) = phi(i) - h;
    ASSERT_TRUE(sim.simulate(p, minus, nullptr, nullptr));
    Eigen::MatrixXd fd = (plus - minus) / (2 * h), exact(sim.cycles(), n);
    for (int j = 0; j < n; ++j) exact.col(j) = dtau.col(j * Reduced::np + i);
    const double error = (fd - exact).cwiseAbs().maxCoeff() / scale;
    std::cout << "  d tau / d " << name << ": max " << scale << " N m per unit, central differences differ by " << error
              << " of it\n";
    EXPECT_GT(scale, 0) << name;
    EXPECT_LT(error, 1e-6) << name;
  }
}

TEST(ClosedLoopSimulator, SensitivitiesMatchCentralDifferences) {
  check_sensitivities(identify::closed_loop_setup(ideal_config()));
}

TEST(ClosedLoopSimulator, SensitivitiesMatchCentralDifferencesWithStepsSplitAtSampling) {
  identify::ClosedLoopSetup setup = identify::closed_loop_setup(ideal_config());
  setup.split_at_sampling = true;
  setup.substeps = 2;
  check_sensitivities(setup);
}

// The generated forward_dynamics_derivatives and the Jet path (ClosedLoopSetup::jet_derivatives)
// compute the same sensitivities in a different order of operations: they agree to round-off,
// on the reduced and the full model (Coulomb friction included), and CLIE takes the same steps.
TEST(ClosedLoopSimulator, GeneratedDerivativesAndJetsGiveTheSameSensitivitiesAndClie) {
  identify::ClosedLoopSetup generated = identify::closed_loop_setup(ideal_config());
  identify::ClosedLoopSetup jet = generated;
  jet.jet_derivatives = true;
  const auto compare = [&](const auto& model_tag, const Eigen::VectorXd& phi) {
    using M = std::decay_t<decltype(model_tag)>;
    Channels tau_g, dtau_g, tau_j, dtau_j;
    ASSERT_TRUE(ClosedLoopSimulator<M>(generated, short_trajectory()).simulate(phi, tau_g, &dtau_g, nullptr));
    ASSERT_TRUE(ClosedLoopSimulator<M>(jet, short_trajectory()).simulate(phi, tau_j, &dtau_j, nullptr));
    const double tau_error = (tau_g - tau_j).cwiseAbs().maxCoeff() / tau_j.cwiseAbs().maxCoeff();
    const double dtau_error = (dtau_g - dtau_j).cwiseAbs().maxCoeff() / dtau_j.cwiseAbs().maxCoeff();
    std::cout << "  " << M::np << " parameters: tau differs by " << tau_error << ", d tau / d phi by " << dtau_error
              << " of its largest entry\n";
    EXPECT_LT(tau_error, 1e-10);
    EXPECT_LT(dtau_error, 1e-9);
  };
  compare(Reduced{}, reduced_truth());
  compare(Full{}, twin::make_truth<Full>(ideal_config()).phi);

  // CLIE both ways from the same start on the same data: the same solution.
  const ClosedLoopSimulator<Reduced> sim_g(generated, short_trajectory()), sim_j(jet, short_trajectory());
  Channels tau, q;
  ASSERT_TRUE(sim_g.simulate(reduced_truth(), tau, nullptr, nullptr, &q));
  io::Log log;
  log.meta.robot = "crane_x7";
  log.meta.trajectory = short_trajectory().name;
  log.meta.source = "twin";
  log.meta.sample_time = sim_g.period();
  for (const auto& j : Full::joints) log.meta.joints.push_back(j.name);
  log.time = Eigen::VectorXd::LinSpaced(sim_g.cycles(), 0, (sim_g.cycles() - 1) * sim_g.period());
  log.q = q;
  log.qd = Eigen::MatrixXd::Zero(sim_g.cycles(), n);
  log.tau = tau;
  twin::Random rng(5);
  for (Eigen::Index k = 0; k < log.tau.size(); ++k) log.tau.data()[k] += 1e-3 * rng.normal();
  identify::ClieOptions options;
  options.max_iterations = 8;
  const preprocess::Samples samples = preprocess::preprocess(log, 0.04, options.preprocess);
  Eigen::VectorXd phi0 = reduced_truth();
  for (int i = 0; i < Reduced::np; ++i) phi0(i) *= (i % 2 ? 1.2 : 0.8);
  const identify::ClieResult rg = identify::clie<Reduced>(sim_g, samples, phi0, options);
  const identify::ClieResult rj = identify::clie<Reduced>(sim_j, samples, phi0, options);
  std::cout << "  CLIE generated: " << rg.iterations << " iterations, cost " << rg.final_cost << ", " << rg.wall
            << " s; Jet: " << rj.iterations << " iterations, cost " << rj.final_cost << ", " << rj.wall << " s\n";
  ASSERT_TRUE(rg.success && rj.success);
  EXPECT_EQ(rg.iterations, rj.iterations);
  EXPECT_NEAR(rg.final_cost, rj.final_cost, 1e-8 * rj.final_cost);
  EXPECT_LT((rg.phi - rj.phi).norm(), 1e-7 * rj.phi.norm());
}

// The full model at the twin's truth reproduces the ideal twin's log: exactly up to the
// integrators when the twin's quantization is made negligible, and within the quantization's
// own effect when it is not. No delay, or rows recording the new command instead of the one
// in effect, would be far off.
TEST(ClosedLoopSimulator, ReproducesTheIdealTwin) {
  const twin::TwinConfig config = ideal_config();
  twin::TwinConfig fine = config;
  for (auto& s : fine.servos) {
    s.encoder_counts = 1 << 30;  // 6e-9 rad steps
    s.current_unit = 1e-12;
  }
  const trajectory::Trajectory& traj = short_trajectory();
  const io::Log quantized = twin::ClosedLoopTwin<Full>(config).run(traj, {});
  const io::Log unquantized = twin::ClosedLoopTwin<Full>(fine).run(traj, {});
  const Eigen::VectorXd phi = twin::make_truth<Full>(config).phi;

  const identify::ClosedLoopSetup setup = identify::closed_loop_setup(config);
  const ClosedLoopSimulator<Full> sim(setup, traj);
  Channels tau;
  ASSERT_TRUE(sim.simulate(phi, tau, nullptr, nullptr));
  ASSERT_EQ(tau.rows(), unquantized.samples());
  identify::ClosedLoopSetup no_delay = setup;
  no_delay.delay = 0;
  Channels tau_no_delay;
  ASSERT_TRUE(ClosedLoopSimulator<Full>(no_delay, traj).simulate(phi, tau_no_delay, nullptr, nullptr));

  const double exact = rms(Eigen::MatrixXd(tau) - unquantized.tau);
  const double wrong_delay = rms(Eigen::MatrixXd(tau_no_delay) - unquantized.tau);
  // Recording the new command instead of the one in effect: every row one cycle early.
  const Eigen::Index rows = tau.rows() - 1;
  const double wrong_row = rms(Eigen::MatrixXd(tau.bottomRows(rows)) - unquantized.tau.topRows(rows));
  const double vs_quantized = rms(Eigen::MatrixXd(tau) - quantized.tau);
  const double quantization = rms(unquantized.tau - quantized.tau);
  const Channels sim_f = lowpassed(tau, 0.04), quant_f = lowpassed(Channels(quantized.tau), 0.04),
                 unq_f = lowpassed(Channels(unquantized.tau), 0.04);
  const double vs_quantized_f = rms(Eigen::MatrixXd(sim_f - quant_f)), quantization_f = rms(Eigen::MatrixXd(unq_f - quant_f));
  std::cout << "  rms torque difference, N m: unquantized twin " << exact << " (delay 0: " << wrong_delay
            << ", rows one cycle early: " << wrong_row << "); ideal twin " << vs_quantized << " (its quantization alone: " << quantization
            << "); after the 10 Hz low-pass " << vs_quantized_f << " (quantization alone " << quantization_f << ")\n";
  // A torque changing by ~0.5 mN m per cycle here: 1e-5 N m leaves no room for a timing
  // error beyond a few percent of a cycle.
  EXPECT_LT(exact, 1e-5);
  EXPECT_GT(wrong_delay, 50 * exact);
  EXPECT_GT(wrong_row, 50 * exact);
  EXPECT_NEAR(vs_quantized, quantization, 0.02 * quantization);
  EXPECT_NEAR(vs_quantized_f, quantization_f, 0.05 * quantization_f + 1e-4);
}

TEST(ClosedLoopSimulator, DivergenceIsReportedNotThrown) {
  const identify::ClosedLoopSetup setup = identify::closed_loop_setup(ideal_config());
  const ClosedLoopSimulator<Reduced> sim(setup, short_trajectory());
  Eigen::VectorXd phi = reduced_truth();
  phi(index_of("IA8")) = -1e-3;  // M(8, 8) = IA8: indefinite at any pose
  Channels tau, dtau;
  identify::Divergence why;
  EXPECT_FALSE(sim.simulate(phi, tau, &dtau, &why));
  EXPECT_TRUE(why.diverged);
  EXPECT_NEAR(why.time, -setup.pre_roll, 1e-12);  // the first stage of the pre-roll
  EXPECT_NE(why.reason.find("not positive definite"), std::string::npos) << why.describe();
  // A hand 50000 times lighter than the controller assumes: M stays positive definite, but
  // the loop gain explodes and joint 8 runs away as soon as the motion starts (at 1.5 s).
  phi(index_of("IA8")) = 1e-7;
  why = {};
  EXPECT_FALSE(sim.simulate(phi, tau, nullptr, &why));
  std::cout << "  " << why.describe() << "\n";
  EXPECT_TRUE(why.diverged);
  EXPECT_GT(why.time, 1.5);
  EXPECT_LT(why.time, 1.6);
  EXPECT_EQ(why.joint, 7);
  EXPECT_NE(why.reason.find("tracking error"), std::string::npos) << why.describe();
}

// Data CLIE's own simulation made at a known phi (plus noise), preprocessed as a log would be:
// from phi perturbed by 25 %, CLIE returns to phi wherever the data determine it.
TEST(Clie, RecoversKnownParametersFromSimulatedData) {
  const identify::ClosedLoopSetup setup = identify::closed_loop_setup(ideal_config());
  const trajectory::Trajectory& traj = short_trajectory();
  const ClosedLoopSimulator<Reduced> sim(setup, traj);
  const Eigen::VectorXd truth = reduced_truth();
  Channels tau, q;
  ASSERT_TRUE(sim.simulate(truth, tau, nullptr, nullptr, &q));

  const double noise = 1e-4;  // N m at 1 kHz
  twin::Random rng(11);
  io::Log log;
  log.meta.robot = "crane_x7";
  log.meta.trajectory = traj.name;
  log.meta.source = "twin";
  log.meta.sample_time = sim.period();
  for (const auto& j : Full::joints) log.meta.joints.push_back(j.name);
  log.time = Eigen::VectorXd::LinSpaced(sim.cycles(), 0, (sim.cycles() - 1) * sim.period());
  log.q = q;
  log.qd = Eigen::MatrixXd::Zero(sim.cycles(), n);
  log.tau = tau;
  for (Eigen::Index k = 0; k < log.tau.size(); ++k) log.tau.data()[k] += noise * rng.normal();
  identify::ClieOptions options;
  const preprocess::Samples samples = preprocess::preprocess(log, 0.02, options.preprocess);

  // How well the samples determine each parameter: sigma (J'J)^-1 at the truth, sigma the
  // filtered noise level, J = -d tau_s / d phi at the samples (the filter is linear).
  Channels dtau;
  ASSERT_TRUE(sim.simulate(truth, tau, &dtau, nullptr));
  dtau = lowpassed(dtau, 0.02);
  const int samples_count = static_cast<int>(samples.time.size());
  Eigen::MatrixXd J(samples_count * n, Reduced::np);
  for (int s = 0; s < samples_count; ++s) {
    const int k = static_cast<int>(std::llround(samples.time(s) / sim.period()));
    for (int j = 0; j < n; ++j) J.row(s * n + j) = dtau.row(k).segment(j * Reduced::np, Reduced::np);
  }
  const double sigma = rms(lowpassed(Channels(log.tau) - tau, 0.02));
  // Columns scaled to unit norm for the SVD: std_i = sigma / |J_i| |V_i. / s|.
  const Eigen::VectorXd column = J.colwise().norm().transpose();
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(J * column.cwiseInverse().asDiagonal(), Eigen::ComputeThinV);
  const Eigen::MatrixXd spread = svd.matrixV() * svd.singularValues().cwiseInverse().asDiagonal();
  const Eigen::VectorXd relative_std =
      (sigma * spread.rowwise().norm()).cwiseQuotient(column).cwiseQuotient(truth.cwiseAbs());

  Eigen::VectorXd phi0 = truth;
  for (int i = 0; i < Reduced::np; ++i) phi0(i) *= (i % 2 ? 1.25 : 0.75);
  options.max_iterations = 50;
  const identify::ClieResult r = identify::clie<Reduced>(sim, samples, phi0, options);
  std::cout << "  CLIE: " << r.termination << "; " << r.iterations << " iterations, " << r.jacobian_evaluations
            << " Jacobians, cost " << r.initial_cost << " -> " << r.final_cost << ", rms " << r.rms_final.transpose()
            << ", " << r.wall << " s\n";
  ASSERT_TRUE(r.success) << r.termination;
  EXPECT_FALSE(r.start_divergence.diverged);
  EXPECT_LT(r.final_cost, 1e-5 * r.initial_cost);
  EXPECT_LT(r.rms_final.maxCoeff(), 2 * sigma);
  EXPECT_LE(r.jacobian_evaluations, r.iterations + 1);  // no Jacobians inside the line search
  EXPECT_TRUE(r.at_bound.empty());
  std::string well;
  for (int i = 0; i < Reduced::np; ++i) {
    const double error = std::abs(r.phi(i) - truth(i)) / std::abs(truth(i));
    // Every parameter where the noise leaves it (the noise-free optimum is the truth), and
    // the well-determined ones to 1e-3.
    EXPECT_LT(error, 5 * relative_std(i)) << Reduced::parameters[i].name;
    if (relative_std(i) < 1e-4) {
      well += std::string(" ") + Reduced::parameters[i].name;
      EXPECT_LT(error, 1e-3) << Reduced::parameters[i].name;
    }
  }
  std::cout << "  to 1e-3 or better:" << well << "\n";
  EXPECT_GE(std::count(well.begin(), well.end(), ' '), 8);
}

// A start whose M is indefinite: no solve, a clear report, no exception.
TEST(Clie, DivergentStartIsReportedWithoutSolving) {
  const identify::ClosedLoopSetup setup = identify::closed_loop_setup(ideal_config());
  const ClosedLoopSimulator<Reduced> sim(setup, short_trajectory());
  Eigen::VectorXd truth = reduced_truth();
  Channels tau, q;
  ASSERT_TRUE(sim.simulate(truth, tau, nullptr, nullptr, &q));
  preprocess::Samples samples;
  samples.interval = 0.04;
  const int stride = 40;
  const int count = (sim.cycles() - 1) / stride + 1;
  samples.time.resize(count);
  samples.tau.resize(count, n);
  for (int s = 0; s < count; ++s) {
    samples.time(s) = s * samples.interval;
    samples.tau.row(s) = tau.row(s * stride);
  }
  Eigen::VectorXd phi0 = truth;
  phi0(index_of("ZZR1")) = -0.05;  // M(1, 1) < 0 at the start posture
  identify::ClieResult r;
  ASSERT_NO_THROW(r = identify::clie<Reduced>(sim, samples, phi0));
  EXPECT_FALSE(r.success);
  EXPECT_TRUE(r.start_divergence.diverged);
  EXPECT_NEAR(r.start_divergence.time, -setup.pre_roll, 1e-12);
  EXPECT_NE(r.start_divergence.reason.find("not positive definite"), std::string::npos);
  EXPECT_NE(r.termination.find("diverges"), std::string::npos) << r.termination;
  EXPECT_EQ(r.iterations, 0);
  // A rotor inertia below its bound is clamped to it, not rejected.
  phi0 = truth;
  phi0(index_of("IA5")) = -1e-3;
  identify::ClieOptions options;
  options.max_iterations = 1;
  options.min_rotor_inertia = 0.004;
  ASSERT_NO_THROW(r = identify::clie<Reduced>(sim, samples, phi0, options));
  EXPECT_FALSE(r.start_divergence.diverged) << r.start_divergence.describe();
  EXPECT_GE(r.phi(index_of("IA5")), options.min_rotor_inertia);
}

}  // namespace

namespace {

// The bounds by standard deviations: the tighter of +-bound_factor |phi0| and +-K sigma applies
// per parameter; a rotor inertia keeps its positive floor; a missing or bad sigma is refused.
TEST(Clie, StdBoundsTakeTheTighterHalfWidth) {
  Eigen::VectorXd phi0(3), sigma(3);
  phi0 << 0.5, -0.002, 0.01;
  sigma << 0.001, 0.1, 0.02;
  identify::ClieOptions o;
  o.std_bound = 10;
  o.scale = sigma;
  const auto b = identify::detail::parameter_bounds(phi0, {false, false, true}, o);
  EXPECT_DOUBLE_EQ(b.lower(0), 0.5 - 0.01);  // 10 sigma = 0.01 < 100 |phi0| = 50
  EXPECT_DOUBLE_EQ(b.upper(0), 0.5 + 0.01);
  EXPECT_DOUBLE_EQ(b.lower(1), -0.002 - 0.2);  // 100 |phi0| = 0.2 < 10 sigma = 1
  EXPECT_DOUBLE_EQ(b.upper(1), -0.002 + 0.2);
  EXPECT_DOUBLE_EQ(b.lower(2), o.min_rotor_inertia);  // 0.01 - 0.2 < 0: the rotor floor
  EXPECT_DOUBLE_EQ(b.upper(2), 0.01 + 0.2);
  o.scale = Eigen::VectorXd::Ones(2);
  EXPECT_THROW(identify::detail::parameter_bounds(phi0, {false, false, true}, o), std::invalid_argument);
  o.scale = Eigen::Vector3d(1, 0, 1);
  EXPECT_THROW(identify::detail::parameter_bounds(phi0, {false, false, true}, o), std::invalid_argument);
}

}  // namespace
