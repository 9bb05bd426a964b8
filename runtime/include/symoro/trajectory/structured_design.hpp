// The paper's structured excitation families for any robot (issue 29), written as a trajectory
// design file (design.hpp's format, robots/crane_x7/trajectories.yaml is one instance):
// single-joint and adjacent-pair primitives at postures inside the joints' limits and audit
// box, at three speed levels, on the grid the paper uses:
//   P<X>01-03  singles             every joint alone, levels 1, 2, 3
//   P<X>04-06  singles_in_phase    pairs (1,2), (4,5), ... in phase, the joints between alone
//   P<X>07-09  singles_opposite    joint 1 alone, pairs (2,3), (4,5), ... in opposite phase
//   AP         adjacent_pairs      (1,2), (3,4), ... in phase, (2,3), (4,5), ... opposite; at
//                                  every posture at level 3, at the last one at levels 1, 2
//   V01-V03    held-out validation: multi-axis waypoints drawn inside the box (seeded)
// Everything not given is derived from the joints: the box is the position limits less the
// margin cut to the audit box, at most +-120 deg around its middle; posture A is its middle, B
// and C move joints 2 and 3 a quarter of the box up and down; amplitudes are a third of the
// box, at most 60 deg, kept inside it; velocity 60 % of the joint's limit, acceleration 5 /s
// times that. CRANE-X7's file is this generator's output for its own postures, amplitudes,
// limits and classes, plus its wrist variants, aggregates and validation motions.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/model_info.hpp"
#include "symoro/trajectory/fourier.hpp"

namespace symoro::trajectory {

struct PrimitiveRanges {
  Eigen::VectorXd amplitude, center;  // rad, per joint
};

struct StructuredDesignOptions {
  std::string robot;
  std::vector<JointInfo> joints;
  double position_margin = 0.034906585039886591;      // rad (2 deg)
  std::map<std::string, Eigen::VectorXd> postures;    // rad; empty: A, B, C as above
  std::map<std::string, PrimitiveRanges> primitives;  // by posture; missing: as above
  Eigen::VectorXd velocity, acceleration;             // at speed factor 1; empty: as above
  std::map<std::string, std::vector<double>> speed_factors{
      {"normal", {0.30, 0.60, 0.90}}, {"proximal", {0.25, 0.50, 0.75}}, {"large", {0.20, 0.40, 0.60}}};
  std::vector<std::string> joint_class;  // per joint; empty: joints 1, 2 proximal, the rest normal
  double start_hold = 1.5, end_hold = 1.5, waypoint_dwell = 0.25, primitive_dwell = 0.5;  // s
  int validation = 3;                                                                     // V trajectories
  std::uint64_t seed = 1;
};

// The working box per joint (rad): the position limits less the margin, cut to the audit box
// and to +-120 deg around its middle.
void structured_box(const StructuredDesignOptions& options, Eigen::VectorXd& lower, Eigen::VectorXd& upper);

// The design file's text. Throws std::invalid_argument for a robot with a prismatic joint (the
// design format is in degrees) or options whose sizes do not match the joints.
std::string structured_design_yaml(const StructuredDesignOptions& options);

// A trajectory entry of the design file holding a Fourier series (`periods` periods from rest at
// `posture` back to it), its coefficients at full precision so that it reads back bit for bit.
std::string fourier_trajectory_yaml(const std::string& name, const std::string& posture, const FourierTrajectory& t,
                                    int periods, const std::string& comment);

}  // namespace symoro::trajectory
