// Joint-space reference trajectories made of point-to-point segments (paper, Appendix B):
// each segment moves all joints from one waypoint to the next along one normalized profile
// s(t) in [0, 1] (continuous acceleration; a constant-velocity phase when the segment is long
// enough), or holds a waypoint. A Trajectory is exact: evaluate(t) gives q, qd, qdd at any t.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::trajectory {

// The normalized point-to-point profile, planned for one segment.
struct Profile {
  double duration = 0;  // s; 0 for an empty move
  double ramp = 0;      // length of each acceleration / deceleration phase, s
  double cruise = 0;    // length of the constant-velocity phase, s (0 when too short)
  // s, ds/dt, d2s/dt2 at time t from the segment start (clamped to [0, duration]).
  void evaluate(double t, double& s, double& sd, double& sdd) const;
};

struct Segment {
  double start = 0;        // s from the trajectory start
  Eigen::VectorXd from, to;  // waypoints (rad or m), one entry per joint; equal for a hold
  Profile profile;
  double end() const { return start + profile.duration; }
};

class Trajectory {
 public:
  std::string name;         // e.g. "PA01"
  std::string family;       // PA PB PC AP AG V
  std::string description;  // one line: posture, primitives, speed
  std::vector<Segment> segments;  // contiguous, in time order, from t = 0

  int joints() const { return segments.empty() ? 0 : static_cast<int>(segments.front().from.size()); }
  double duration() const { return segments.empty() ? 0.0 : segments.back().end(); }
  // Reference at time t; before 0 and after duration() the end waypoints are held.
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd,
                Eigen::Ref<Eigen::VectorXd> qdd) const;
};

}  // namespace symoro::trajectory
