// The excitation design's NLP for Ipopt, its random starts, and the dense check
// (excitation/design.hpp).
#include "symoro/excitation/design.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "symoro/identify/detail/ipopt_lock.hpp"
#include "symoro/parallel/farm.hpp"

namespace symoro::excitation {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInfinity = 1e20;  // beyond Ipopt's infinity (1e19)

using Clock = std::chrono::steady_clock;

std::string joint_name(const identify::IdentificationModel& m, int j) {
  return m.description().joints[static_cast<std::size_t>(j)].name;
}

// The sampled limits keep the whole motion inside: q - mid, qd and qdd are trigonometric
// polynomials of degree L, and one sampled at N > 2L equally spaced instants stays within
// 1 / cos(pi L / N) of its largest sample (Ehlich and Zeller, 1964). The dense check proves it.
double sampling_factor(int harmonics, int samples) { return std::cos(kPi * harmonics / samples); }

// The torque and workspace constraints are nonlinear and couple every coefficient: one row per
// instant made Ipopt's KKT factorization (MUMPS, dense fronts) most of the time. Each is
// aggregated over the instants instead by the Kreisselmeier-Steinhauser function
//   KS(v) = max v + log(sum_k exp(s (v_k - max v))) / s  >=  max v,
// a smooth, conservative maximum (by at most log(N) / s): torque over its limit with
// s = 60 (a few % of the limit), a half-space's distance with s = 200 / m (a few mm).
constexpr double kTorqueSharpness = 60;
constexpr double kWorkspaceSharpness = 200;

// KS(v) and its weights d KS / d v_k (a softmax, summing to 1).
double aggregate(const Eigen::VectorXd& v, double s, Eigen::VectorXd& weights) {
  const double top = v.maxCoeff();
  weights = (s * (v.array() - top)).exp().matrix();
  const double sum = weights.sum();
  weights /= sum;
  return top + std::log(sum) / s;
}

class DesignProblem : public Ipopt::TNLP {
 public:
  DesignProblem(const ExcitationCriterion& criterion, const ExcitationDesignOptions& options, Eigen::VectorXd x0)
      : c_(criterion), o_(options), x0_(std::move(x0)) {
    const FourierBasis& b = c_.basis();
    n_ = b.joints();
    N_ = b.samples();
    L_ = b.harmonics();
    V_ = b.variables();
    torque_ = options.limits.torque.size() > 0;
    H_ = static_cast<int>(options.workspace.size());
    rp_ = 2 * n_;
    rv_ = rp_ + N_ * n_;
    ra_ = rv_ + N_ * n_;
    rt_ = ra_ + N_ * n_;
    rw_ = rt_ + (torque_ ? 2 * n_ : 0);
    m_ = rw_ + H_;
  }
  const Eigen::VectorXd& solution() const { return solution_; }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& style) override {
    n = V_;
    m = m_;
    nnz_jac_g = 2 * n_ * L_ + 3 * N_ * n_ * 2 * L_ + (rw_ - rt_ + (m_ - rw_)) * V_;
    nnz_h_lag = 0;
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index, Ipopt::Number* g_l,
                       Ipopt::Number* g_u) override {
    std::fill(x_l, x_l + V_, -kInfinity);
    std::fill(x_u, x_u + V_, kInfinity);
    for (const int j : o_.held) {  // held joints: their coefficients fixed at 0
      std::fill(x_l + j * 2 * L_, x_l + (j + 1) * 2 * L_, 0.0);
      std::fill(x_u + j * 2 * L_, x_u + (j + 1) * 2 * L_, 0.0);
    }
    std::fill(g_l, g_l + rp_, 0.0);
    std::fill(g_u, g_u + rp_, 0.0);
    const double s = sampling_factor(L_, N_);
    const auto& lim = o_.limits;
    for (int k = 0; k < N_; ++k)
      for (int j = 0; j < n_; ++j) {
        const int r = k * n_ + j;
        const double mid = (lim.lower(j) + lim.upper(j)) / 2 - o_.start(j),
                     half = (lim.upper(j) - lim.lower(j)) / 2 * s;
        g_l[rp_ + r] = mid - half;
        g_u[rp_ + r] = mid + half;
        g_l[rv_ + r] = -lim.velocity(j) * s;
        g_u[rv_ + r] = lim.velocity(j) * s;
        g_l[ra_ + r] = -lim.acceleration(j) * s;
        g_u[ra_ + r] = lim.acceleration(j) * s;
        if (torque_) {
        }
      }
    // The aggregated rows: KS(+tau_j / limit), KS(-tau_j / limit) <= margin; KS(space) <= 0.
    for (int i = rt_; i < m_; ++i) {
      g_l[i] = -kInfinity;
      g_u[i] = i < rw_ ? o_.torque_margin : 0.0;
    }
    return true;
  }

  bool get_starting_point(Ipopt::Index, bool, Ipopt::Number* x, bool, Ipopt::Number*, Ipopt::Number*, Ipopt::Index,
                          bool, Ipopt::Number*) override {
    std::copy(x0_.data(), x0_.data() + V_, x);
    return true;
  }

  // The value alone where Ipopt asks for the value: its line search and restoration phase try
  // many points whose gradient it never asks for, and the gradient costs a derivative of the
  // inverse dynamics per instant and joint.
  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    if (!objective(x, false)) return false;
    f = f_;
    return true;
  }
  bool eval_grad_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number* grad) override {
    if (!objective(x, true)) return false;
    std::copy(grad_.data(), grad_.data() + V_, grad);
    return true;
  }

  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* g) override {
    const Eigen::Map<const Eigen::VectorXd> X(x, V_);
    const FourierBasis& b = c_.basis();
    const int B = b.block();
    for (int j = 0; j < n_; ++j) {
      g[2 * j] = X.segment(j * B, L_).sum();
      double s = 0;
      for (int l = 0; l < L_; ++l) s += (l + 1) * X(j * B + L_ + l);
      g[2 * j + 1] = s;
    }
    for (int k = 0; k < N_; ++k)
      for (int j = 0; j < n_; ++j) {
        const int r = k * n_ + j;
        g[rp_ + r] = b.bq().row(k).dot(X.segment(j * B, B));
        g[rv_ + r] = b.bqd().row(k).dot(X.segment(j * B, B));
        g[ra_ + r] = b.bqdd().row(k).dot(X.segment(j * B, B));
      }
    if (!nonlinear(x)) return false;
    for (int r = rt_; r < m_; ++r) g[r] = ks_(r - rt_);
    return true;
  }

  bool eval_jac_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index, Ipopt::Index* rows,
                  Ipopt::Index* cols, Ipopt::Number* values) override {
    const FourierBasis& b = c_.basis();
    const int B = b.block();
    int e = 0;
    auto put = [&](int row, int col, double v) {
      if (values)
        values[e] = v;
      else {
        rows[e] = row;
        cols[e] = col;
      }
      ++e;
    };
    for (int j = 0; j < n_; ++j) {
      for (int l = 0; l < L_; ++l) put(2 * j, j * B + l, 1.0);
      for (int l = 0; l < L_; ++l) put(2 * j + 1, j * B + L_ + l, l + 1.0);
    }
    for (const auto& [first, basis] : {std::pair{rp_, &b.bq()}, std::pair{rv_, &b.bqd()}, std::pair{ra_, &b.bqdd()}})
      for (int k = 0; k < N_; ++k)
        for (int j = 0; j < n_; ++j)
          for (int i = 0; i < B; ++i) put(first + k * n_ + j, j * B + i, (*basis)(k, i));
    if (values && !nonlinear(x)) return false;
    for (int r = rt_; r < m_; ++r)
      for (int i = 0; i < V_; ++i) put(r, i, values ? Jks_(r - rt_, i) : 0.0);
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    solution_ = Eigen::Map<const Eigen::VectorXd>(x, V_);
  }

 private:
  bool same(const Eigen::VectorXd& cached, const Ipopt::Number* x) const {
    return cached.size() == V_ && std::equal(x, x + V_, cached.data());
  }
  // An exception must not unwind through Ipopt: a failed evaluation makes it cut the step.
  // The value (and with `gradient` its gradient) at x, cached: the value is the same whether or
  // not the gradient is asked for.
  bool objective(const Ipopt::Number* x, bool gradient) {
    if (same(fx_, x) && (grad_ok_ || !gradient || !f_ok_)) return f_ok_;
    fx_ = Eigen::Map<const Eigen::VectorXd>(x, V_);
    grad_ok_ = false;
    try {
      const auto f = c_.value(fx_, gradient ? &grad_ : nullptr);
      f_ok_ = f.has_value() && std::isfinite(*f) && (!gradient || grad_.allFinite());
      if (f_ok_) f_ = *f;
      grad_ok_ = f_ok_ && gradient;
    } catch (...) {
      f_ok_ = false;
    }
    return f_ok_;
  }
  bool nonlinear(const Ipopt::Number* x) {
    if (!torque_ && H_ == 0) return true;
    if (same(gx_, x)) return g_ok_;
    gx_ = Eigen::Map<const Eigen::VectorXd>(x, V_);
    try {
      ks_.resize(m_ - rt_);
      Jks_.resize(m_ - rt_, V_);
      if (torque_) {
        Eigen::MatrixXd J;
        const Eigen::MatrixXd tau = c_.torque(gx_, o_.nominal, &J);
        for (int j = 0; j < n_; ++j)
          for (int sign : {1, -1}) {
            const int r = 2 * j + (sign > 0 ? 0 : 1);
            const Eigen::VectorXd v = sign / o_.limits.torque(j) * tau.col(j);
            Eigen::VectorXd w;
            ks_(r) = aggregate(v, kTorqueSharpness, w);
            Jks_.row(r).setZero();
            for (int k = 0; k < N_; ++k) Jks_.row(r) += w(k) * sign / o_.limits.torque(j) * J.row(k * n_ + j);
          }
      }
      if (H_ > 0) {
        Eigen::MatrixXd J;
        const Eigen::MatrixXd ws = c_.workspace(gx_, o_.workspace, &J);
        for (int h = 0; h < H_; ++h) {
          const int r = rw_ - rt_ + h;
          Eigen::VectorXd w;
          ks_(r) = aggregate((ws.col(h).array() + o_.workspace_margin).matrix(), kWorkspaceSharpness, w);
          Jks_.row(r).setZero();
          for (int k = 0; k < N_; ++k) Jks_.row(r) += w(k) * J.row(k * H_ + h);
        }
      }
      g_ok_ = ks_.allFinite() && Jks_.allFinite();
    } catch (...) {
      g_ok_ = false;
    }
    return g_ok_;
  }

  const ExcitationCriterion& c_;
  const ExcitationDesignOptions& o_;
  Eigen::VectorXd x0_, solution_;
  int n_ = 0, N_ = 0, L_ = 0, V_ = 0, H_ = 0, m_ = 0;
  // First rows: positions, velocities, accelerations at every instant; torques (2 per joint)
  // and half-spaces (1 each) aggregated over the instants.
  int rp_ = 0, rv_ = 0, ra_ = 0, rt_ = 0, rw_ = 0;
  bool torque_ = false;
  Eigen::VectorXd fx_, grad_, gx_;
  double f_ = 0;
  bool f_ok_ = false, grad_ok_ = false, g_ok_ = false;
  Eigen::VectorXd ks_;
  Eigen::MatrixXd Jks_;
};

// Random coefficients at rest at t = 0, scaled per joint to half of its limits by the
// closed-form bounds (trajectory/fourier.hpp).
Eigen::VectorXd random_start(const FourierBasis& basis, const ExcitationDesignOptions& options, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  trajectory::FourierTrajectory t;
  t.w = basis.pulsation();
  const int n = basis.joints(), L = basis.harmonics();
  t.a.resize(n, L);
  t.b.resize(n, L);
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < L; ++l) {
      t.a(j, l) = normal(rng) / (l + 1);
      t.b(j, l) = normal(rng) / (l + 1);
    }
  t.come_to_rest_at(options.start);
  const Eigen::VectorXd pb = t.position_bound(), vb = t.velocity_bound(), ab = t.acceleration_bound();
  for (int j = 0; j < n; ++j) {
    const double room =
        std::min(options.limits.upper(j) - options.start(j), options.start(j) - options.limits.lower(j));
    // |q - start| <= 2 sum r / (w l): the series' offset moves with b.
    const double s = 0.5 * std::min({room / (2 * pb(j)), options.limits.velocity(j) / vb(j),
                                     options.limits.acceleration(j) / ab(j)});
    t.a.row(j) *= s;
    t.b.row(j) *= s;
  }
  Eigen::VectorXd x = basis.coefficients(t);
  for (const int j : options.held) x.segment(j * basis.block(), basis.block()).setZero();
  return x;
}

// The statuses after which Ipopt's point is a design (optimal, acceptable, or stopped by a limit
// at a point it computed normally); the rest (invalid number, restoration failed, infeasible,
// errors) leave no design.
bool solved(Ipopt::ApplicationReturnStatus s) {
  return s == Ipopt::Solve_Succeeded || s == Ipopt::Solved_To_Acceptable_Level ||
         s == Ipopt::Maximum_Iterations_Exceeded || s == Ipopt::Maximum_CpuTime_Exceeded ||
         s == Ipopt::Search_Direction_Becomes_Too_Small || s == Ipopt::Feasible_Point_Found;
}

std::string status_name(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
      return "converged";
    case Ipopt::Solved_To_Acceptable_Level:
      return "acceptable";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "iteration limit";
    case Ipopt::Infeasible_Problem_Detected:
      return "infeasible";
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return "step too small";
    case Ipopt::Restoration_Failed:
      return "restoration failed";
    case Ipopt::Error_In_Step_Computation:
      return "step failed";
    case Ipopt::Invalid_Number_Detected:
      return "invalid number";
    default:
      return fmt::format("Ipopt status {}", static_cast<int>(s));
  }
}

void refuse_unmeetable(const identify::IdentificationModel& model, const ExcitationDesignOptions& options) {
  const identify::ModelDescription& d = model.description();
  const int n = d.nq;
  const auto& lim = options.limits;
  auto sized = [n](const Eigen::VectorXd& v) { return v.size() == n; };
  if (!sized(options.start) || !sized(lim.lower) || !sized(lim.upper) || !sized(lim.velocity) ||
      !sized(lim.acceleration) || (lim.torque.size() > 0 && !sized(lim.torque)))
    throw std::invalid_argument(fmt::format("design_excitation: the start pose and the limits need {} joints", n));
  for (const int j : options.held)
    if (j < 0 || j >= n) throw std::invalid_argument(fmt::format("design_excitation: held joint index {}", j));
  if (lim.torque.size() > 0 && options.nominal.size() != d.np)
    throw std::invalid_argument(
        fmt::format("design_excitation: torque limits need the nominal model's {} parameters", d.np));
  for (int j = 0; j < n; ++j) {
    const std::string name = joint_name(model, j);
    if (!(lim.velocity(j) > 0))
      throw ExcitationInfeasible(
          fmt::format("velocity limit of joint {} ({}) is {}: it must be > 0", j + 1, name, lim.velocity(j)));
    if (!(lim.acceleration(j) > 0))
      throw ExcitationInfeasible(
          fmt::format("acceleration limit of joint {} ({}) is {}: it must be > 0", j + 1, name, lim.acceleration(j)));
    if (!(options.start(j) > lim.lower(j) && options.start(j) < lim.upper(j)))
      throw ExcitationInfeasible(
          fmt::format("position limit of joint {} ({}): the start {:.6g} is not inside [{:.6g}, {:.6g}]", j + 1, name,
                      options.start(j), lim.lower(j), lim.upper(j)));
  }
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  if (lim.torque.size() > 0) {
    identify::StateDerivatives rest;
    model.state_derivatives(options.start, zero, zero, options.nominal, true, rest);
    for (int j = 0; j < n; ++j)
      if (std::abs(rest.tau(j)) > lim.torque(j) * options.torque_margin)
        throw ExcitationInfeasible(fmt::format(
            "torque limit of joint {} ({}): holding the start pose takes {:.4g} (gravity, nominal model), more than {} "
            "% of "
            "its limit {:.4g}",
            j + 1, joint_name(model, j), rest.tau(j), std::lround(100 * options.torque_margin), lim.torque(j)));
  }
  if (!options.workspace.empty()) {
    const Eigen::VectorXd v = half_space_values(d.frames, options.start, options.workspace);
    for (std::size_t h = 0; h < options.workspace.size(); ++h)
      if (v(static_cast<Eigen::Index>(h)) > 0)
        throw ExcitationInfeasible(
            fmt::format("workspace half-space {}: frame {}'s origin at the start pose is {:.4g} beyond it",
                        options.workspace[h].name, options.workspace[h].frame, v(static_cast<Eigen::Index>(h))));
  }
}

}  // namespace

std::vector<ExcitationSlack> check_excitation(const identify::IdentificationModel& model,
                                              const trajectory::FourierTrajectory& t,
                                              const ExcitationDesignOptions& options) {
  const int n = model.description().nq;
  const bool torque = options.limits.torque.size() > 0;
  std::vector<ExcitationSlack> worst{
      {"position", "", kInfinity, 0}, {"velocity", "", kInfinity, 0}, {"acceleration", "", kInfinity, 0}};
  if (torque) worst.push_back({"torque", "", kInfinity, 0});
  if (!options.workspace.empty()) worst.push_back({"workspace", "", kInfinity, 0});
  // The name is looked up only when a new tightest slack is found (not per joint per millisecond).
  auto note = [](ExcitationSlack& w, double slack, const auto& where, double time) {
    if (slack < w.slack) w = {w.constraint, where(), slack, time};
  };
  const int cycles = static_cast<int>(std::lround(t.period() / options.check_period));
  Eigen::VectorXd q, qd, qdd;
  identify::StateDerivatives d;
  for (int k = 0; k <= cycles; ++k) {
    const double time = k * options.check_period;
    t.evaluate(time, q, qd, qdd);
    for (int j = 0; j < n; ++j) {
      const auto name = [&] { return joint_name(model, j); };
      note(worst[0], std::min(options.limits.upper(j) - q(j), q(j) - options.limits.lower(j)), name, time);
      note(worst[1], options.limits.velocity(j) - std::abs(qd(j)), name, time);
      note(worst[2], options.limits.acceleration(j) - std::abs(qdd(j)), name, time);
    }
    if (torque) {
      model.state_derivatives(q, qd, qdd, options.nominal, true, d);
      for (int j = 0; j < n; ++j)
        note(
            worst[3], options.limits.torque(j) - std::abs(d.tau(j)), [&] { return joint_name(model, j); }, time);
    }
    if (!options.workspace.empty()) {
      const Eigen::VectorXd v = half_space_values(model.description().frames, q, options.workspace);
      for (std::size_t h = 0; h < options.workspace.size(); ++h)
        note(
            worst.back(), -v(static_cast<Eigen::Index>(h)), [&] { return options.workspace[h].name; }, time);
    }
  }
  return worst;
}

namespace {

// One start's outcome: its record, and the point its solve ended at.
struct StartOutcome {
  ExcitationStart result;
  Eigen::VectorXd x;
};

StartOutcome run_start(const identify::IdentificationModel& model, const ExcitationCriterion& criterion,
                       const ExcitationDesignOptions& options, const Eigen::VectorXd& x0) {
  const auto ts = Clock::now();
  const FourierBasis& basis = criterion.basis();
  auto* problem = new DesignProblem(criterion, options, x0);
  const Ipopt::SmartPtr<Ipopt::TNLP> owner = problem;
  ExcitationStart result;
  {
    std::lock_guard<std::mutex> lock(identify::detail::ipopt_mutex());
    Ipopt::SmartPtr<Ipopt::IpoptApplication> app = new Ipopt::IpoptApplication(false);  // prints nothing
    auto& ip = *app->Options();
    ip.SetIntegerValue("print_level", 0);
    ip.SetStringValue("sb", "yes");
    ip.SetNumericValue("tol", options.tolerance);
    ip.SetNumericValue("constr_viol_tol", 1e-9);
    ip.SetIntegerValue("max_iter", options.max_iterations);
    ip.SetStringValue("hessian_approximation", "limited-memory");
    ip.SetStringValue("mu_strategy", "adaptive");
    // MUMPS's approximate minimum degree ordering: its default choice orders the KKT system's
    // dense aggregated rows (torque, workspace) poorly; AMD halves the time per iteration on a
    // 7-joint arm (Panda, 20 s period, 8 harmonics: 12.4 s -> 6.7 s for 150 iterations).
    ip.SetIntegerValue("mumps_pivot_order", 0);
    if (app->Initialize("") != Ipopt::Solve_Succeeded)
      throw std::runtime_error("design_excitation: Ipopt did not initialize");
    const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(owner);
    result.status = status_name(status);
    result.solved = solved(status);
    if (const auto stats = app->Statistics(); Ipopt::IsValid(stats)) result.iterations = stats->IterationCount();
  }
  result.criterion = -std::numeric_limits<double>::infinity();
  if (problem->solution().size() == basis.variables()) {
    if (const auto f = criterion.value(problem->solution())) {
      result.criterion = -*f;
      const auto slack = check_excitation(model, basis.trajectory(problem->solution(), options.name), options);
      result.worst =
          *std::min_element(slack.begin(), slack.end(),
                            [](const ExcitationSlack& a, const ExcitationSlack& b) { return a.slack < b.slack; });
      // A start counts only when its solve ended normally and its point passes the dense check:
      // a point Ipopt left after "invalid number" or "restoration failed" is no design, even
      // inside the limits (a NaN torque limit gave one, written with rc 0).
      result.passed = result.solved && result.worst.slack >= 0;
    }
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - ts).count();
  return {result, problem->solution()};
}

// A start's outcome as text, from its process to the design: a line per field, numbers as
// hexadecimal floats (exact).
std::string outcome_text(const StartOutcome& o) {
  const ExcitationStart& r = o.result;
  std::string t =
      fmt::format("{}\n{} {} {} {:a} {:a}\n{}\n{}\n{:a} {:a}\n{}", r.status, int(r.solved), int(r.passed), r.iterations,
                  r.criterion, r.seconds, r.worst.constraint, r.worst.where, r.worst.slack, r.worst.time, o.x.size());
  for (Eigen::Index i = 0; i < o.x.size(); ++i) t += fmt::format(" {:a}", o.x(i));
  return t + "\n";
}

StartOutcome outcome_from_text(const std::string& text) {
  std::istringstream in(text);
  StartOutcome o;
  ExcitationStart& r = o.result;
  std::string line;
  auto number = [](std::istream& s) {
    std::string w;
    s >> w;
    return std::strtod(w.c_str(), nullptr);  // hexadecimal floats, inf and nan
  };
  std::getline(in, r.status);
  std::getline(in, line);
  {
    std::istringstream l(line);
    int solved = 0, passed = 0;
    l >> solved >> passed >> r.iterations;
    r.solved = solved != 0;
    r.passed = passed != 0;
    r.criterion = number(l);
    r.seconds = number(l);
  }
  std::getline(in, r.worst.constraint);
  std::getline(in, r.worst.where);
  std::getline(in, line);
  {
    std::istringstream l(line);
    r.worst.slack = number(l);
    r.worst.time = number(l);
  }
  Eigen::Index n = 0;
  in >> n;
  o.x.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) o.x(i) = number(in);
  if (!in) throw std::runtime_error("design_excitation: a start's outcome came back unreadable");
  return o;
}

}  // namespace

ExcitationDesign design_excitation(const identify::IdentificationModel& model, const ExcitationDesignOptions& options) {
  const auto t0 = Clock::now();
  refuse_unmeetable(model, options);
  const int n = model.description().nq;
  const int samples = options.samples > 0 ? options.samples : std::max(100, 20 * options.harmonics);
  ExcitationCriterion criterion(model, FourierBasis(n, options.harmonics, options.period, samples, options.start));
  criterion.set_parameter_map(options.parameter_map);
  const FourierBasis& basis = criterion.basis();

  ExcitationDesign out;
  Eigen::VectorXd best_x;
  double best = -std::numeric_limits<double>::infinity();
  // The starts, each from the same process state in a forked process of its own when there are
  // cores to spare (Ipopt's solver is not thread-safe, and keeps state between solves), else in
  // turn; either way chosen below in their order.
  const int count = std::max(1, options.starts);
  std::vector<Eigen::VectorXd> x0(static_cast<std::size_t>(count));
  for (int s = 0; s < count; ++s) {
    x0[static_cast<std::size_t>(s)] =
        random_start(basis, options, options.seed * 1000003ULL + static_cast<std::uint64_t>(s));
    if (s == 0) {
      criterion.scale_columns_at(x0[0]);
      out.scales = criterion.scales();
    }
  }
  std::vector<StartOutcome> outcomes(static_cast<std::size_t>(count));
  if (count > 1 && options.workers != 1 && parallel::place().ranks == 1) {
    std::vector<std::string> tasks;
    for (int s = 0; s < count; ++s) tasks.push_back(std::to_string(s));
    parallel::Farm farm;
    farm.work = [&](const std::string& task, const std::function<void(const std::string&)>& emit) {
      emit(outcome_text(run_start(model, criterion, options, x0[std::stoul(task)])));
    };
    farm.on_result = [&](std::size_t task, const std::string& text) { outcomes[task] = outcome_from_text(text); };
    farm.on_end = [&](const parallel::TaskEnd& e) {
      if (!e.failed) return;
      outcomes[e.task] = StartOutcome{};
      outcomes[e.task].result.status = "failed: " + e.failure;
    };
    parallel::FarmOptions fo;
    fo.workers = options.workers;
    fo.isolate = true;
    parallel::run_farm(tasks, farm, fo);
  } else {
    for (int s = 0; s < count; ++s)
      outcomes[static_cast<std::size_t>(s)] = run_start(model, criterion, options, x0[static_cast<std::size_t>(s)]);
  }
  for (int s = 0; s < count; ++s) {
    const StartOutcome& r = outcomes[static_cast<std::size_t>(s)];
    if (r.result.passed && r.result.criterion > best) {
      best = r.result.criterion;
      best_x = r.x;
      out.chosen = s;
    }
    out.starts.push_back(r.result);
    if (r.result.passed) out.starts.back().trajectory = basis.trajectory(r.x, options.name);
  }
  if (out.chosen < 0 &&
      std::none_of(out.starts.begin(), out.starts.end(), [](const ExcitationStart& r) { return r.solved; })) {
    std::string statuses;
    for (const auto& r : out.starts) statuses += (statuses.empty() ? "" : ", ") + r.status;
    throw ExcitationInfeasible("no start's solve ended normally (Ipopt: " + statuses + ")");
  }
  if (out.chosen < 0) {
    const auto& w =
        std::min_element(out.starts.begin(), out.starts.end(), [](const ExcitationStart& a, const ExcitationStart& b) {
          return a.worst.slack > b.worst.slack;
        })->worst;
    throw ExcitationInfeasible(
        w.constraint.empty()
            ? std::string("no start excites every base parameter (the regressor stays rank deficient)")
            : fmt::format("no start met every limit: the closest passes the {} limit of {} by {:.4g} at t = {:.3f} s",
                          w.constraint, w.where, -w.slack, w.time));
  }
  out.trajectory = basis.trajectory(best_x, options.name);
  out.criterion = best;
  out.slack = check_excitation(model, out.trajectory, options);
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

}  // namespace symoro::excitation
