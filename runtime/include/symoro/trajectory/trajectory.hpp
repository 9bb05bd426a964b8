// Joint-space reference trajectories made of point-to-point segments (paper, Appendix B):
// each segment moves all joints from one waypoint to the next along one normalized profile
// s(t) in [0, 1] (continuous acceleration; a constant-velocity phase when the segment is long
// enough), or holds a waypoint. A Trajectory is exact: evaluate(t) gives q, qd, qdd at any t.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::trajectory {

struct FourierTrajectory;  // fourier.hpp

// The normalized point-to-point profile, planned for one segment.
struct Profile {
  double duration = 0;  // s; 0 for an empty move
  double ramp = 0;      // length of each acceleration / deceleration phase, s
  double cruise = 0;    // length of the constant-velocity phase, s (0 when too short)
  // s, ds/dt, d2s/dt2 at time t from the segment start (clamped to [0, duration]).
  void evaluate(double t, double& s, double& sd, double& sdd) const;

  // The move from s = 0 to 1 with |ds/dt| <= velocity and |d2s/dt2| <= acceleration (1/s,
  // 1/s^2): sine-squared acceleration ramps, a(t) = a_peak sin^2(pi t / ramp), at the
  // acceleration limit, then a cruise at the velocity limit; when 1 is too short for a cruise,
  // the peak velocity is lowered instead (ramps only, still at the acceleration limit).
  static Profile plan(double velocity, double acceleration);
  // Standing still for `duration` (s stays 0).
  static Profile hold(double duration);
  bool moves() const { return ramp > 0; }
  double peak_velocity() const;      // 1/s, reached at the end of the first ramp
  double peak_acceleration() const;  // 1/s^2, reached in the middle of the first ramp
};

struct Segment {
  double start = 0;          // s from the trajectory start
  Eigen::VectorXd from, to;  // waypoints (rad or m), one entry per joint; equal for a hold
  Profile profile;
  std::string label;  // what the segment belongs to: "hold", "dwell", "transition",
                      // a primitive such as "P4@B'" or "P2,3(+,-)@C", "waypoint 3", "fourier"
  // A periodic excitation (its whole periods, from rest at `from` back to rest there): set, the
  // segment follows this series from its start instead of the profile (which only holds the
  // duration).
  std::shared_ptr<const FourierTrajectory> periodic;
  double end() const { return start + profile.duration; }
};

class Trajectory {
 public:
  std::string name;               // e.g. "PA01"
  std::string family;             // PA PB PC AP AG V
  std::string description;        // one line: posture, primitives, speed
  std::vector<Segment> segments;  // contiguous, in time order, from t = 0

  int joints() const { return segments.empty() ? 0 : static_cast<int>(segments.front().from.size()); }
  double duration() const { return segments.empty() ? 0.0 : segments.back().end(); }
  // Reference at time t; before 0 and after duration() the end waypoints are held.
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd,
                Eigen::Ref<Eigen::VectorXd> qdd) const;
};

}  // namespace symoro::trajectory
