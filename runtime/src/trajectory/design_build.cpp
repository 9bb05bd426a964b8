// Assembling a designed trajectory: the primitives of Appendix B become waypoints, the
// waypoints become synchronized point-to-point moves, separated by dwells, framed by holds.
#include <algorithm>
#include <limits>

#include "design_data.hpp"
#include "symoro/trajectory/move.hpp"

namespace symoro::trajectory {

namespace {

std::string sign(int s) { return s > 0 ? "+" : "-"; }

// "P4@B'" or "P2,3(+,-)@C".
std::string primitive_label(const PrimitiveSpec& p, const std::string& posture) {
  std::string label = "P" + std::to_string(p.joints[0] + 1);
  if (p.joints.size() == 2)
    label += "," + std::to_string(p.joints[1] + 1) + "(" + sign(p.signs[0]) + "," + sign(p.signs[1]) + ")";
  return label + "@" + posture;
}

class Assembler {
 public:
  Assembler(const Design& d, const TrajectorySpec& spec) : d_(d), spec_(spec) {
    trajectory_.name = spec.name;
    trajectory_.family = spec.family;
    trajectory_.description = spec.description;
    at_ = d.postures.at(spec.posture);
  }

  Trajectory run() {
    dwell(d_.start_hold, "hold");
    for (const ItemSpec& item : spec_.items) {
      if (item.kind == ItemSpec::Kind::Waypoints)
        waypoints(item);
      else if (item.kind == ItemSpec::Kind::Fourier)
        periodic(item);
      else
        for (const PrimitiveSpec& p : item.primitives) primitive(item, p);
    }
    // Back to the trajectory's posture, and at rest for the end hold instead of the last dwell.
    transition(d_.postures.at(spec_.posture), spec_.speed, "");
    auto& segments = trajectory_.segments;
    while (!segments.empty() && !segments.back().profile.moves() && !segments.back().periodic && segments.size() > 1)
      segments.pop_back();
    dwell(d_.end_hold, "hold");
    return std::move(trajectory_);
  }

 private:
  // The speed factor of a move at `level`: the item's class, or the slowest class of the joints
  // that move (proximal and large-amplitude joints slow down the whole move).
  double factor(const std::vector<int>& moving, int level, const std::string& item_class) const {
    if (!item_class.empty()) return d_.speed_factors.at(item_class)[level - 1];
    double f = std::numeric_limits<double>::infinity();
    for (int j : moving) f = std::min(f, d_.speed_factors.at(d_.joint_class[j])[level - 1]);
    return f;
  }

  std::vector<int> moving(const Eigen::VectorXd& to) const {
    std::vector<int> joints;
    for (Eigen::Index j = 0; j < to.size(); ++j)
      if (to[j] != at_[j]) joints.push_back(static_cast<int>(j));
    return joints;
  }

  // A point-to-point move at speed factor f: velocity f v, acceleration f^2 a (time / f).
  void move(const Eigen::VectorXd& to, double f, const std::string& label) {
    Segment s = plan_move(now(), at_, to, f * d_.velocity, f * f * d_.acceleration);
    at_ = to;
    if (!s.profile.moves()) return;
    s.label = label;
    trajectory_.segments.push_back(std::move(s));
  }

  void dwell(double duration, const std::string& label) {
    if (duration <= 0) return;
    Segment s = plan_hold(now(), at_, duration);
    s.label = label;
    trajectory_.segments.push_back(std::move(s));
  }

  // To `to` when the arm is elsewhere, then the dwell that ends a primitive or a transition.
  void transition(const Eigen::VectorXd& to, int level, const std::string& item_class) {
    const std::vector<int> joints = moving(to);
    if (joints.empty()) return;
    move(to, factor(joints, level, item_class), "transition");
    dwell(d_.primitive_dwell, "dwell");
  }

  // P_j or P_j,j+1 around qbar = posture + the center offsets of its own joints.
  void primitive(const ItemSpec& item, const PrimitiveSpec& p) {
    const PrimitiveParameters& par = d_.primitive_parameters.at(d_.base_posture.at(item.posture));
    Eigen::VectorXd center = d_.postures.at(item.posture);
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(center.size());
    for (std::size_t k = 0; k < p.joints.size(); ++k) {
      const int j = p.joints[k];
      center[j] += par.center[j];
      delta[j] = p.signs[k] * par.amplitude[j];
    }
    transition(center, item.speed, item.speed_class);
    const double f = factor(p.joints, item.speed, item.speed_class);
    const std::string label = primitive_label(p, item.posture);
    move(center - delta, f, label);
    dwell(d_.waypoint_dwell, label);
    move(center + delta, f, label);
    dwell(d_.waypoint_dwell, label);
    move(center, f, label);
    dwell(d_.primitive_dwell, "dwell");
  }

  void waypoints(const ItemSpec& item) {
    for (std::size_t k = 0; k < item.waypoints.size(); ++k) {
      const Eigen::VectorXd& to = item.waypoints[k];
      const std::vector<int> joints = moving(to);
      if (joints.empty()) continue;
      const std::string label = "waypoint " + std::to_string(k + 1);
      move(to, factor(joints, item.speed, item.speed_class), label);
      dwell(k + 1 < item.waypoints.size() ? d_.waypoint_dwell : d_.primitive_dwell, label);
    }
  }

  // Whole periods of a Fourier series from rest where the arm is, back to rest there.
  void periodic(const ItemSpec& item) {
    auto series = std::make_shared<FourierTrajectory>(*item.fourier);
    series->q0 = at_;
    for (int l = 1; l <= series->harmonics(); ++l) series->q0 += series->b.col(l - 1) / (series->w * l);
    Segment s = plan_hold(now(), at_, item.periods * series->period());
    s.label = "fourier";
    s.periodic = std::move(series);
    trajectory_.segments.push_back(std::move(s));
    dwell(d_.primitive_dwell, "dwell");
  }

  double now() const { return trajectory_.duration(); }

  const Design& d_;
  const TrajectorySpec& spec_;
  Trajectory trajectory_;
  Eigen::VectorXd at_;  // where the arm is at the end of the segments so far
};

}  // namespace

Trajectory assemble(const Design& design, const TrajectorySpec& spec) { return Assembler(design, spec).run(); }

}  // namespace symoro::trajectory
