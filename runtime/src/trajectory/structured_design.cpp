#include "symoro/detail/numbers.hpp"
#include "symoro/trajectory/structured_design.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

namespace symoro::trajectory {

namespace {

using symoro::detail::kDeg;
constexpr double kMaxHalfBox = 120 * kDeg;
constexpr double kMaxAmplitude = 60 * kDeg;

std::string list(const Eigen::VectorXd& v, double scale, const char* format = "{:.6g}") {
  std::string out = "[";
  for (Eigen::Index j = 0; j < v.size(); ++j) {
    double x = v(j) / scale;
    if (std::abs(x) < 5e-7) x = 0;  // no "-0" or 1e-15 in a file people read
    out += (j ? ", " : "") + fmt::format(fmt::runtime(format), x);
  }
  return out + "]";
}

// Pairs and singles of a pattern, 1-based joints.
std::string single(int j) { return fmt::format("{{single: [{}]}}", j); }
std::string pair(int j, bool opposite) {
  return fmt::format("{{pair: [{}, {}]{}}}", j, j + 1, opposite ? ", signs: [1, -1]" : "");
}

std::string join(const std::vector<std::string>& items) {
  std::string out = "[";
  for (std::size_t k = 0; k < items.size(); ++k) out += (k ? ", " : "") + items[k];
  return out + "]";
}

}  // namespace

void structured_box(const StructuredDesignOptions& options, Eigen::VectorXd& lower, Eigen::VectorXd& upper) {
  const int n = static_cast<int>(options.joints.size());
  lower.resize(n);
  upper.resize(n);
  for (int j = 0; j < n; ++j) {
    const JointInfo& J = options.joints[static_cast<std::size_t>(j)];
    double lo = std::max(J.lower + options.position_margin, J.audit_lower),
           hi = std::min(J.upper - options.position_margin, J.audit_upper);
    if (!(hi > lo))
      lo = J.lower + options.position_margin, hi = J.upper - options.position_margin;  // an audit box beside the range
    const double mid = (lo + hi) / 2;
    lower(j) = std::max(lo, mid - kMaxHalfBox);
    upper(j) = std::min(hi, mid + kMaxHalfBox);
  }
}

namespace {

// The postures given, or three about the box's middle: A at it, B and C a quarter of the box up
// and down on joints 2 and 3.
std::map<std::string, Eigen::VectorXd> design_postures(const StructuredDesignOptions& options,
                                                       const Eigen::VectorXd& mid, const Eigen::VectorXd& width) {
  const int n = static_cast<int>(mid.size());
  std::map<std::string, Eigen::VectorXd> postures = options.postures;
  if (postures.empty()) {
    postures["A"] = mid;
    postures["B"] = mid;
    postures["C"] = mid;
    for (int j : {1, 2})
      if (j < n) {
        postures["B"](j) += 0.25 * width(j);
        postures["C"](j) -= 0.25 * width(j);
      }
  }
  return postures;
}

// The primitives' amplitude and center offset per posture: given, or the largest swing inside
// the box (about the box's middle for a posture at its edge).
std::string primitives_yaml(const StructuredDesignOptions& options,
                            const std::map<std::string, Eigen::VectorXd>& postures, const Eigen::VectorXd& lo,
                            const Eigen::VectorXd& hi) {
  const int n = static_cast<int>(lo.size());
  const Eigen::VectorXd width = hi - lo, mid = (lo + hi) / 2;
  std::string y;
  y += "\n# Amplitude a_j and center offset c_j per posture: qbar +- a_j stays inside the box.\nprimitives:\n";
  for (const auto& [name, q] : postures) {
    PrimitiveRanges r;
    if (const auto given = options.primitives.find(name); given != options.primitives.end()) {
      r = given->second;
    } else {
      r.center = Eigen::VectorXd::Zero(n);
      r.amplitude.resize(n);
      for (int j = 0; j < n; ++j) {
        const double room = std::min(hi(j) - q(j), q(j) - lo(j));
        r.amplitude(j) = std::max(0.0, std::min({width(j) / 3, kMaxAmplitude, room - 1 * kDeg}));
        if (r.amplitude(j) < 5 * kDeg)  // a posture at the edge of the box: swing around its middle instead
          r.center(j) = mid(j) - q(j), r.amplitude(j) = std::min(width(j) / 3, kMaxAmplitude);
      }
    }
    y += fmt::format("  {}:\n    amplitude: {}\n    center:    {}\n", name, list(r.amplitude, kDeg),
                     list(r.center, kDeg));
  }

  return y;
}

// The patterns (1-based joints): singles, in phase, opposite, and adjacent pairs when there are
// two joints or more (has_pairs).
std::string patterns_yaml(int n, bool& has_pairs) {
  std::string y;
  // The patterns (1-based joints).
  std::vector<std::string> singles_list, in_phase, opposite, pairs_in, pairs_opp;
  for (int j = 1; j <= n; ++j) singles_list.push_back(std::to_string(j));
  for (int j = 1; j <= n; j += 3) {
    if (j + 1 <= n)
      in_phase.push_back(pair(j, false));
    else
      in_phase.push_back(single(j));
    if (j + 2 <= n) in_phase.push_back(single(j + 2));
  }
  opposite.push_back(single(1));
  for (int j = 2; j <= n; j += 2) opposite.push_back(j + 1 <= n ? pair(j, true) : single(j));
  for (int j = 1; j + 1 <= n; j += 2) pairs_in.push_back(fmt::format("[{}, {}]", j, j + 1));
  for (int j = 2; j + 1 <= n; j += 2) pairs_opp.push_back(fmt::format("[{}, {}]", j, j + 1));
  y += "\npatterns:\n";
  y += "  singles: [{single: " + join(singles_list) + "}]\n";
  y += "  singles_in_phase: " + join(in_phase) + "\n";
  y += "  singles_opposite: " + join(opposite) + "\n";
  std::vector<std::string> adjacent;
  if (!pairs_in.empty()) adjacent.push_back("{pair: " + join(pairs_in) + "}");
  if (!pairs_opp.empty()) adjacent.push_back("{pair: " + join(pairs_opp) + ", signs: [1, -1]}");
  has_pairs = !adjacent.empty();
  if (has_pairs) y += "  adjacent_pairs: " + join(adjacent) + "\n";

  return y;
}

// The trajectories: each posture x single pattern x speed level, the adjacent pairs, and the
// held-out validation waypoints (six each, inside the middle 70 % of the box).
std::string trajectories_yaml(const StructuredDesignOptions& options,
                              const std::map<std::string, Eigen::VectorXd>& postures, bool has_pairs,
                              const Eigen::VectorXd& mid, const Eigen::VectorXd& width) {
  const int n = static_cast<int>(mid.size());
  std::string y;
  y += "\ntrajectories:\n";
  const char* patterns[] = {"singles", "singles_in_phase", "singles_opposite"};
  for (const auto& [name, q] : postures) {
    for (int p = 0; p < 3; ++p)
      for (int level = 1; level <= 3; ++level)
        y += fmt::format("  - {{name: P{}{:02d}, posture: {}, speed: {}, sequence: [{{pattern: {}}}]}}\n", name,
                         3 * p + level, name, level, patterns[p]);
    y += "\n";
  }
  if (has_pairs) {
    int k = 0;
    for (const auto& [name, q] : postures)
      y += fmt::format("  - {{name: AP{:02d}, posture: {}, speed: 3, sequence: [{{pattern: adjacent_pairs}}]}}\n", ++k,
                       name);
    const std::string last = postures.rbegin()->first;
    for (int level = 1; level <= 2; ++level)
      y += fmt::format("  - {{name: AP{:02d}, posture: {}, speed: {}, sequence: [{{pattern: adjacent_pairs}}]}}\n", ++k,
                       last, level);
    y += "\n";
  }
  // Held-out validation: six multi-axis waypoints each, drawn inside the middle 70 % of the box.
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> u(-0.35, 0.35);
  const std::string first = postures.begin()->first;
  for (int v = 1; v <= options.validation; ++v) {
    y += fmt::format("  - name: V{:02d}\n    posture: {}\n    speed: 2\n    sequence:\n      - waypoints: [", v, first);
    for (int w = 0; w < 6; ++w) {
      Eigen::VectorXd q(n);
      for (int j = 0; j < n; ++j) q(j) = mid(j) + u(rng) * width(j);
      y += (w ? ",\n                    " : "") + list(q, kDeg, "{:.1f}");
    }
    y += "]\n";
  }
  return y;
}

}  // namespace

std::string structured_design_yaml(const StructuredDesignOptions& options) {
  const int n = static_cast<int>(options.joints.size());
  for (const JointInfo& j : options.joints)
    if (j.type != JointType::Revolute)
      throw std::invalid_argument(std::string("structured design: joint ") + j.name +
                                  " is prismatic; the design format covers revolute joints");
  auto sized = [n](const Eigen::VectorXd& v) { return v.size() == 0 || v.size() == n; };
  if (!sized(options.velocity) || !sized(options.acceleration) ||
      (!options.joint_class.empty() && static_cast<int>(options.joint_class.size()) != n))
    throw std::invalid_argument(fmt::format("structured design: limits and classes need {} joints", n));
  Eigen::VectorXd lo, hi;
  structured_box(options, lo, hi);
  for (int j = 0; j < n; ++j)
    if (!(hi(j) > lo(j)))
      throw std::invalid_argument(
          fmt::format("structured design: joint {} ({}) has no room inside its limits less the margin", j + 1,
                      options.joints[static_cast<std::size_t>(j)].name));
  const Eigen::VectorXd width = hi - lo, mid = (lo + hi) / 2;

  const std::map<std::string, Eigen::VectorXd> postures = design_postures(options, mid, width);
  for (const auto& [name, q] : postures)
    if (q.size() != n)
      throw std::invalid_argument(fmt::format("structured design: posture {} needs {} joints", name, n));
  Eigen::VectorXd velocity = options.velocity, acceleration = options.acceleration;
  if (velocity.size() == 0) {
    velocity.resize(n);
    for (int j = 0; j < n; ++j) velocity(j) = 0.6 * options.joints[static_cast<std::size_t>(j)].velocity;
  }
  if (acceleration.size() == 0) acceleration = 5.0 * velocity;
  std::vector<std::string> classes = options.joint_class;
  if (classes.empty())
    for (int j = 0; j < n; ++j) classes.push_back(j < 2 ? "proximal" : "normal");

  std::string y;
  y += fmt::format("# {} identification and validation trajectories: the paper's structured families (single-joint\n",
                   options.robot);
  y += "# and adjacent-pair primitives on a posture x pattern x speed grid), written by `dynid excite`\n";
  y += "# (symoro/trajectory/structured_design.hpp). Units: deg, rad/s and rad/s^2 at speed factor 1, s.\n";
  y += "# Review the postures and amplitudes: they are derived from the joint limits, not from the arm's\n";
  y += "# surroundings.\n\n";
  y += fmt::format("robot: {}\njoints: [", options.robot);
  for (int j = 0; j < n; ++j) y += (j ? ", " : "") + std::string(options.joints[static_cast<std::size_t>(j)].name);
  y += "]\n\nlimits:\n";
  y += fmt::format("  position_margin: {:.6g}\n", options.position_margin / kDeg);
  y += fmt::format("  velocity: {}\n  acceleration: {}\n\n", list(velocity, 1), list(acceleration, 1));
  y += "speed_factors:\n";
  for (const auto& [c, f] : options.speed_factors) {
    y += fmt::format("  {}: [", c);
    for (std::size_t k = 0; k < f.size(); ++k) y += fmt::format("{}{:.6g}", k ? ", " : "", f[k]);
    y += "]\n";
  }
  y += "joint_class: [";
  for (int j = 0; j < n; ++j) y += (j ? ", " : "") + classes[static_cast<std::size_t>(j)];
  y += "]\n\n";
  y += fmt::format(
      "timing:\n  start_hold: {:.6g}\n  end_hold: {:.6g}\n  waypoint_dwell: {:.6g}\n  primitive_dwell: {:.6g}\n\n",
      options.start_hold, options.end_hold, options.waypoint_dwell, options.primitive_dwell);
  y += "postures:\n";
  for (const auto& [name, q] : postures) y += fmt::format("  {}: {}\n", name, list(q, kDeg));
  y += primitives_yaml(options, postures, lo, hi);

  bool has_pairs = false;
  y += patterns_yaml(n, has_pairs);

  y += trajectories_yaml(options, postures, has_pairs, mid, width);
  return y;
}

std::string fourier_trajectory_yaml(const std::string& name, const std::string& posture, const FourierTrajectory& t,
                                    int periods, const std::string& comment) {
  auto matrix = [](const Eigen::MatrixXd& m) {
    std::string out = "[";
    for (Eigen::Index j = 0; j < m.rows(); ++j) {
      out += j ? ",\n                 [" : "[";
      for (Eigen::Index l = 0; l < m.cols(); ++l) out += fmt::format("{}{:.17g}", l ? ", " : "", m(j, l));
      out += "]";
    }
    return out + "]";
  };
  std::string y;
  if (!comment.empty()) y += "  # " + comment + "\n";
  y += fmt::format("  - name: {}\n    posture: {}\n    speed: 1\n    sequence:\n      - fourier:\n", name, posture);
  y += fmt::format("          period: {:.17g}\n          periods: {}\n", t.period(), periods);
  y += "          a: " + matrix(t.a) + "\n";
  y += "          b: " + matrix(t.b) + "\n";
  return y;
}

}  // namespace symoro::trajectory
