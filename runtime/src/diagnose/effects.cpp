#include "symoro/diagnose/effects.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "spread_average.hpp"

namespace symoro::diagnose {

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

std::string joint_text(const DesignStack& d, int j) {
  return j >= 1 && j <= static_cast<int>(d.joint_names.size()) ? fmt::format("joint {} ({})", j, d.joint_names[j - 1])
                                                               : fmt::format("joint {}", j);
}

// A row added to the table past the diagnosis's named kinds, with a joint law: handled by its row.
bool added_law(EffectKind kind) { return kind > EffectKind::Payload && effect_info(kind).row->law; }

// Whether an added law is averaged over the velocity spread: a law of qd alone (a law of q is
// blurred by no spread). Traced once per kind: effect_terms asks it at every sample.
bool averaged(EffectKind kind) {
  static const std::vector<bool> by_kind = [] {
    std::vector<bool> out;
    for (const EffectInfo& e : effect_catalogue()) {
      const bool added = added_law(e.kind);
      const detail::LawDependence on = added ? detail::law_dependence(e.row->law) : detail::LawDependence{};
      out.push_back(added && on.qd && !on.q);
    }
    return out;
  }();
  return by_kind.at(static_cast<std::size_t>(kind));
}

bool has_parameter(const DesignStack& d, const std::string& name) {
  for (const auto& p : d.parameters)
    if (p == name) return true;
  return false;
}

}  // namespace

namespace {

// The diagnosis's effects in EffectKind's order, each a row of the effect table by its name.
constexpr std::array<std::string_view, 10> kDiagnosisOrder{
    "coulomb",          "stribeck",        "offset",          "viscous_asymmetry", "position_harmonics",
    "inertia_products", "torque_constant", "actuation_delay", "backlash",          "payload"};
static_assert(kDiagnosisOrder.size() == static_cast<std::size_t>(EffectKind::Payload) + 1);

static_assert(every_name_has_a_row(&EffectRow::diagnosis, kDiagnosisOrder),
              "a diagnosis effect without its row in symoro/effect_table.hpp");

}  // namespace

// The diagnosis's effects: kDiagnosisOrder's, then the table's further rows with a diagnosis name.
const std::vector<EffectInfo>& effect_catalogue() {
  static const std::vector<EffectInfo> v = [] {
    std::vector<const EffectRow*> rows;
    for (std::string_view name : kDiagnosisOrder) rows.push_back(find_effect(&EffectRow::diagnosis, name));
    for (const EffectRow& row : kEffectTable)
      if (!row.diagnosis.empty() && std::find(rows.begin(), rows.end(), &row) == rows.end()) rows.push_back(&row);
    std::vector<EffectInfo> out;
    for (const EffectRow* row : rows)
      out.push_back({static_cast<EffectKind>(out.size()), row, row->diagnosis.data(), row->title.data()});
    return out;
  }();
  return v;
}

// Measured: on an RX-90 whose static friction fades as exp(-(|qd| / vs)^1.5), between the two
// laws, looking for both named Tustin's at 2.40 N m for 1.5 (the Gaussian alone: 1.72).
bool only_when_named(EffectKind kind) { return added_law(kind); }

const EffectInfo& effect_info(EffectKind kind) {
  for (const auto& e : effect_catalogue())
    if (e.kind == kind) return e;
  throw std::logic_error("effect kind without catalogue entry");
}

EffectKind effect_kind(const std::string& name) {
  std::string known;
  for (const auto& e : effect_catalogue()) {
    if (name == e.name) return e.kind;
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw std::invalid_argument("unknown effect '" + name + "' (known: " + known + ")");
}

std::string Candidate::key() const {
  std::string k = std::string(effect_info(kind).name) + ":" + std::to_string(joint);
  if (kind == EffectKind::Stribeck) k += fmt::format("@{:g}~{:g}", stribeck_velocity, coulomb_velocity);
  if (kind == EffectKind::Coulomb) k += fmt::format("@{:g}", coulomb_velocity);
  if (added_law(kind)) k += fmt::format("@{:g}~{:g}", velocity, averaged(kind) ? coulomb_velocity : 0.0);
  return k;
}

std::string Candidate::label() const {
  const EffectInfo& e = effect_info(kind);
  std::string s = e.title;
  if (kind == EffectKind::Stribeck)
    s += fmt::format(" (vs = {:g} rad/s, velocity spread {:g} rad/s)", stribeck_velocity, coulomb_velocity);
  if (kind == EffectKind::Coulomb) s += fmt::format(" (velocity spread {:g} rad/s)", coulomb_velocity);
  if (added_law(kind) && velocity > 0) s += fmt::format(" (v = {:g} rad/s", velocity);
  if (added_law(kind) && averaged(kind))
    s += fmt::format("{}velocity spread {:g} rad/s", velocity > 0 ? ", " : " (", coulomb_velocity);
  if (added_law(kind) && (velocity > 0 || averaged(kind))) s += ")";
  if (kind == EffectKind::InertiaProducts || kind == EffectKind::Payload) return s + fmt::format(", link {}", joint);
  if (joint == 0) return s;
  return s + fmt::format(", joint {}", joint);
}

Candidate joint_candidate(EffectKind kind, int j, const std::vector<int>& orders) {
  const EffectRow& row = *effect_info(kind).row;
  Candidate c;
  c.kind = kind;
  c.joint = j;
  c.orders = orders;
  if (added_law(kind)) c.velocity = row.velocity_scale.empty() ? 0.0 : row.default_velocity;
  if (added_law(kind) && !averaged(kind)) c.coulomb_velocity = 0;
  for (const EffectParameterName& p : effect_parameter_names(row, j, orders)) {
    c.parameters.push_back(p.name);
    c.units.emplace_back(row.unit);
  }
  return c;
}

namespace {

// An effect the options let the diagnosis look for.
bool wanted(const CandidateOptions& options, EffectKind k) {
  if (options.only.empty()) return !only_when_named(k);
  for (const auto& n : options.only)
    if (n == effect_info(k).name) return true;
  return false;
}

// Joint j's Coulomb candidates, one per spread, and Stribeck candidates, one per velocity and
// spread of at most half of it.
void add_friction(const DesignStack& d, const CandidateOptions& options, int j, const std::vector<double>& spreads,
                  const std::vector<double>& velocities, std::vector<Candidate>& out) {
  // Named as the variant compiles it (smooth_coulomb: FC<j>); not a candidate where the model
  // already has Coulomb friction on the joint (OpenSYMORO's FS<j>, or a compiled FC<j>).
  const std::string fc = joint_candidate(EffectKind::Coulomb, j).parameters[0];
  const std::string fst = joint_candidate(EffectKind::Stribeck, j).parameters[0];
  if (wanted(options, EffectKind::Coulomb) && !has_parameter(d, fmt::format("FS{}", j)) && !has_parameter(d, fc))
    for (double spread : spreads) {
      out.push_back(joint_candidate(EffectKind::Coulomb, j));
      out.back().coulomb_velocity = spread;
    }
  if (wanted(options, EffectKind::Stribeck) && !has_parameter(d, fst))
    for (double vs : velocities)
      for (double spread : spreads)
        if (2 * spread <= vs) {
          out.push_back(joint_candidate(EffectKind::Stribeck, j));
          out.back().stribeck_velocity = vs;
          out.back().coulomb_velocity = spread;
        }
}

// Joint j's candidates of the table's added laws (only its friction laws: `friction_only`): one
// per velocity scale when the law has one, and per velocity spread of at most half of it when it
// is averaged over the spread; not where the model already has its parameters.
void add_laws(const DesignStack& d, const CandidateOptions& options, int j, const std::vector<double>& velocities,
              const std::vector<double>& spreads, bool friction_only, std::vector<Candidate>& out) {
  for (const EffectInfo& e : effect_catalogue()) {
    if (!added_law(e.kind) || e.row->scope != EffectScope::Joint || !wanted(options, e.kind)) continue;
    if (friction_only && !friction_law(e.kind)) continue;
    const Candidate made = joint_candidate(e.kind, j);
    bool held = false;
    for (const auto& p : made.parameters) held |= has_parameter(d, p);
    if (held) continue;
    for (double v : e.row->velocity_scale.empty() ? std::vector<double>{0.0} : velocities)
      for (double spread : averaged(e.kind) ? spreads : std::vector<double>{0.0})
        if (v == 0 || 2 * spread <= v) {
          out.push_back(made);
          out.back().velocity = v;
          out.back().coulomb_velocity = spread;
        }
  }
}

}  // namespace

bool friction_law(EffectKind kind) {
  const EffectRow& row = *effect_info(kind).row;
  return kind == EffectKind::Coulomb || kind == EffectKind::Stribeck ||
         (added_law(kind) && !row.velocity_scale.empty() && row.positive && row.scope == EffectScope::Joint);
}

std::vector<Candidate> friction_options(const DesignStack& d, const CandidateOptions& options, int joint) {
  std::vector<Candidate> out;
  add_friction(d, options, joint, options.refined_spreads, options.refined_stribeck_velocities, out);
  add_laws(d, options, joint, options.refined_law_velocities, options.refined_spreads, true, out);
  return out;
}

std::vector<Candidate> candidates(const DesignStack& d, const CandidateOptions& options) {
  std::vector<Candidate> out;
  const int n = d.joints;
  for (int j = 1; j <= n; ++j) {
    // A joint's effect, unless the model already has one of its parameters.
    auto add = [&](EffectKind k, const std::vector<int>& orders = {}) {
      if (!wanted(options, k)) return;
      Candidate c = joint_candidate(k, j, orders);
      for (const auto& p : c.parameters)
        if (has_parameter(d, p)) return;
      out.push_back(std::move(c));
    };
    add_friction(d, options, j, options.coulomb_velocities, options.stribeck_velocities, out);
    add(EffectKind::Offset);
    add(EffectKind::ViscousAsymmetry);
    if (!options.harmonic_orders.empty()) add(EffectKind::PositionHarmonics, options.harmonic_orders);
    const bool drive = d.rotor_inertia_index(j - 1) >= 0 && d.viscous_index(j - 1) >= 0;
    add(EffectKind::TorqueConstant);
    if (drive) add(EffectKind::Backlash);
    add_laws(d, options, j, options.law_velocities, options.coulomb_velocities, false, out);
    // Products of inertia of link j from the full model.
    if (wanted(options, EffectKind::InertiaProducts)) {
      const EffectRow& row = *effect_info(EffectKind::InertiaProducts).row;
      const std::vector<std::string> families = effect_words(row.families);
      Candidate c;
      c.kind = EffectKind::InertiaProducts;
      c.joint = j;
      for (std::size_t i = 0; i < d.full_extra_names.size(); ++i) {
        const std::string& f = d.full_extra_families[i];
        if (d.full_extra_joints[i] == j && std::find(families.begin(), families.end(), f) != families.end()) {
          c.full_columns.push_back(static_cast<int>(i));
          c.parameters.push_back(d.full_extra_names[i]);
          c.units.emplace_back(row.unit);
        }
      }
      if (!c.full_columns.empty()) out.push_back(c);
    }
  }
  // A payload changes the last link's inertial parameters, which a refit absorbs: it is a
  // candidate only when the identified parameters are held.
  if (wanted(options, EffectKind::Payload) && d.held() && d.payload_link > 0 && d.payload_map.cols() == 4) {
    Candidate c;
    c.kind = EffectKind::Payload;
    c.joint = d.payload_link;
    c.parameters = {"PM", "PMX", "PMY", "PMZ"};
    c.units = {"kg", "kg*m", "kg*m", "kg*m"};
    out.push_back(c);
  }
  if (wanted(options, EffectKind::ActuationDelay)) {
    Candidate c;
    c.kind = EffectKind::ActuationDelay;
    c.parameters = {"DELAY"};
    c.units = {"s"};
    out.push_back(c);
  }
  return out;
}

Eigen::MatrixXd effect_columns(const Candidate& c, const DesignStack& d, const FitState& fit) {
  const int n = d.joints, S = d.samples();
  const int j = c.joint - 1;
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(d.rows(), static_cast<Eigen::Index>(c.parameters.size()));
  auto row = [n](int s, int joint) { return static_cast<Eigen::Index>(s) * n + joint; };
  if (sample_local(c.kind)) {
    const auto it = d.effect_terms.find(c.key());
    const Eigen::Index m = X.cols();
    std::vector<double> v(static_cast<std::size_t>(m));
    for (int s = 0; s < S; ++s) {
      if (it != d.effect_terms.end()) {
        X.row(row(s, j)) = it->second.row(s);
      } else {
        effect_terms(c, d.q(s, j), d.qd(s, j), v.data());
        for (Eigen::Index i = 0; i < m; ++i) X(row(s, j), i) = v[static_cast<std::size_t>(i)];
      }
    }
    return X;
  }
  switch (c.kind) {
    case EffectKind::Coulomb:
    case EffectKind::Stribeck:
    case EffectKind::Offset:
    case EffectKind::ViscousAsymmetry:
    case EffectKind::PositionHarmonics:
      break;  // sample-local, above
    case EffectKind::InertiaProducts:
      for (std::size_t i = 0; i < c.full_columns.size(); ++i) X.col(i) = d.full_extra.col(c.full_columns[i]);
      break;
    case EffectKind::Payload:
      X = d.W * d.payload_map;
      break;
    case EffectKind::TorqueConstant:
      for (int s = 0; s < S; ++s) X(row(s, j), 0) = -fit.tau_model(row(s, j));
      break;
    case EffectKind::ActuationDelay: {
      Eigen::MatrixXd tm(S, n);
      for (int s = 0; s < S; ++s) tm.row(s) = fit.tau_model.segment(row(s, 0), n).transpose();
      X.col(0) = d.stacked(d.rate(tm));
      break;
    }
    case EffectKind::Backlash: {
      // The rotor leads the link by half the play in the direction of the mesh torque (the
      // link-side torque: the model's minus the drive's own IA qdd + FV qd), so the motor
      // torque carries IA d2(delta)/dt2 + FV d(delta)/dt that the link's motion does not show.
      // delta switches sharply (a smoothed sign over a few percent of the joint's torque), so
      // it is made as the data were: at the logs' rate, then through the stack's low-pass.
      const double ia = fit.phi(static_cast<Eigen::Index>(d.rotor_inertia_index(j)));
      const double fv = fit.phi(static_cast<Eigen::Index>(d.viscous_index(j)));
      Eigen::MatrixXd mesh(S, 1);
      for (int s = 0; s < S; ++s) mesh(s, 0) = fit.tau_model(row(s, j)) - ia * d.qdd(s, j) - fv * d.qd(s, j);
      const double scale = 0.05 * std::sqrt(mesh.squaredNorm() / std::max(S, 1)) + 1e-9;
      const auto sigma = d.filtered(mesh, [scale](double m) { return std::tanh(m / scale); });
      for (int s = 0; s < S; ++s) X(row(s, j), 0) = 0.5 * (ia * sigma.accel(s, 0) + fv * sigma.rate(s, 0));
      break;
    }
  }
  return X;
}

// Every joint law is; Coulomb's and Stribeck's are the diagnosis's own (averaged over a spread).
bool sample_local(EffectKind kind) { return effect_info(kind).row->law != nullptr; }

void effect_terms(const Candidate& c, double q, double qd, double* out) {
  switch (c.kind) {
    // The laws sign(v) and sign(v) exp(-(v / vs)^2) averaged over v ~ N(qd, spread^2).
    case EffectKind::Coulomb:
      out[0] = std::erf(qd / (std::sqrt(2.0) * c.coulomb_velocity));
      break;
    case EffectKind::Stribeck: {
      // The product of the two Gaussians (the law's exp(-a v^2), the spread's) is one Gaussian
      // in v, centred at b qd / (a + b), over which the sign's mean is an erf.
      const double a = 1 / (c.stribeck_velocity * c.stribeck_velocity),
                   b = 1 / (2 * c.coulomb_velocity * c.coulomb_velocity);
      out[0] = std::sqrt(b / (a + b)) * std::exp(-a * b / (a + b) * qd * qd) * std::erf(b * qd / std::sqrt(a + b));
      break;
    }
    default: {
      // The row's joint law, per parameter in the order they are named: per order, each family.
      const EffectRow& row = *effect_info(c.kind).row;
      if (!row.law) throw std::logic_error("effect_terms: not a sample-local effect");
      const int families = effect_word_count(row.families);
      const std::size_t orders = std::max<std::size_t>(c.orders.size(), 1);
      for (std::size_t o = 0; o < orders; ++o)
        for (int f = 0; f < families; ++f)
          *out++ = averaged(c.kind)
                       ? detail::spread_average(row.law, q, qd, c.coulomb_velocity, f, c.velocity,
                                                c.orders.empty() ? 0 : c.orders[o])
                       : LawValues::evaluate(row.law, q, qd, f, c.velocity, c.orders.empty() ? 0 : c.orders[o]);
    }
  }
}

double variant_velocity(const Candidate& c) {
  if (c.kind == EffectKind::Coulomb) return c.coulomb_velocity * std::sqrt(std::acos(-1.0) / 2);
  if (c.kind == EffectKind::Stribeck) return c.stribeck_velocity;
  return c.velocity;
}

// The effect table's check: a level, a play, a mass or a delay must be positive. (A torque cannot
// answer its command before it is sent: a negative delay is another misfit's shape, seen against
// a study's accepted parameters: -3.39 ms, not a delay.)
bool physical(const Candidate& c, const Eigen::VectorXd& theta) {
  return !effect_info(c.kind).row->positive || theta(0) > 0;
}

Magnitude magnitude(const Candidate& c, const Eigen::VectorXd& theta, const Eigen::VectorXd& sd) {
  Magnitude m;
  auto pm = [](double v, double e, const char* unit, double scale, int digits) {
    return fmt::format("{:.{}f} +- {:.{}f} {}", v * scale, digits, e * scale, digits, unit);
  };
  switch (c.kind) {
    default: {  // each parameter, in the table's unit ("N*m" read "N m")
      std::string unit(effect_info(c.kind).row->unit);
      std::replace(unit.begin(), unit.end(), '*', ' ');
      for (Eigen::Index i = 0; i < theta.size(); ++i) {
        m.values.push_back(theta(i));
        m.names.push_back(c.parameters[i]);
        const std::string value = pm(theta(i), sd(i), unit.c_str(), 1, 4);
        m.text +=
            theta.size() == 1 ? value : fmt::format("{}{} = {}", m.text.empty() ? "" : ", ", c.parameters[i], value);
      }
      break;
    }
    case EffectKind::PositionHarmonics:
      for (std::size_t i = 0; i < c.orders.size(); ++i) {
        const double a = std::hypot(theta(2 * i), theta(2 * i + 1));
        m.values.push_back(a);
        m.names.push_back(fmt::format("amplitude {}", c.orders[i]));
        m.text += fmt::format("{}order {}: {:.4f} N m", m.text.empty() ? "" : ", ", c.orders[i], a);
      }
      break;
    case EffectKind::InertiaProducts:
      for (Eigen::Index i = 0; i < theta.size(); ++i) {
        m.values.push_back(theta(i));
        m.names.push_back(c.parameters[i]);
        m.text += fmt::format("{}{} = {:.3e} kg m^2", m.text.empty() ? "" : ", ", c.parameters[i], theta(i));
      }
      break;
    case EffectKind::TorqueConstant:
      m.values = {theta(0)};
      m.names = {c.parameters[0]};
      m.text = pm(theta(0), sd(0), "%", 100, 2);
      break;
    case EffectKind::ActuationDelay:
      m.values = {theta(0)};
      m.names = {"DELAY"};
      m.text = pm(theta(0), sd(0), "ms", 1000, 2);
      break;
    case EffectKind::Backlash:
      m.values = {theta(0)};
      m.names = {c.parameters[0]};
      m.text = pm(theta(0), sd(0), "deg", kDeg, 3);
      break;
    case EffectKind::Payload: {
      // The mass, then its centre in the link's frame (first moments over the mass).
      const double mass = theta(0);
      m.values = {mass};
      m.names = {"mass"};
      m.text = pm(mass, sd(0), "kg", 1, 4);
      if (std::abs(mass) > 0) {
        const Eigen::Vector3d p = theta.segment<3>(1) / mass;
        m.values.insert(m.values.end(), {p(0), p(1), p(2)});
        m.names.insert(m.names.end(), {"x", "y", "z"});
        m.text += fmt::format(" at ({:.1f}, {:.1f}, {:.1f}) mm", 1e3 * p(0), 1e3 * p(1), 1e3 * p(2));
      }
      break;
    }
  }
  return m;
}

}  // namespace symoro::diagnose
