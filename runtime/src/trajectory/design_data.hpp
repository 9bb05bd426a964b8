// The trajectory design as read from robots/<robot>/trajectories.yaml, validated and in SI
// units (rad, rad/s, rad/s^2, s; joints 0-based). Private to the trajectory library.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/model_info.hpp"
#include "symoro/trajectory/fourier.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::trajectory {

// One primitive: P_j (one joint, sign +1) or P_j,j+1 (two adjacent joints, signs +-1).
struct PrimitiveSpec {
  std::vector<int> joints;  // 0-based
  std::vector<int> signs;   // one per joint
};

// One step of a trajectory's sequence, with patterns and sweeps expanded.
struct ItemSpec {
  enum class Kind { Primitives, Waypoints, Fourier };
  Kind kind = Kind::Primitives;
  std::vector<PrimitiveSpec> primitives;             // Kind::Primitives, in order
  std::vector<Eigen::VectorXd> waypoints;            // Kind::Waypoints, rad
  std::shared_ptr<const FourierTrajectory> fourier;  // Kind::Fourier: w, a, b (q0 from where it starts)
  int periods = 1;                                   // Kind::Fourier
  std::string posture;                               // e.g. "A" or "C'"
  int speed = 1;                                     // level, 1-based
  std::string speed_class;                           // empty: the slowest class of the moving joints
  std::string summary;                               // for the trajectory's description
  int line = 0;
};

struct TrajectorySpec {
  std::string name, family, description, posture;
  int speed = 1;
  std::vector<ItemSpec> items;
  int line = 0;
};

// A primitive's amplitude a_j and center offset c_j at one nominal posture, rad.
struct PrimitiveParameters {
  Eigen::VectorXd amplitude, center;
};

struct Design {
  std::filesystem::path path;
  std::string robot;
  std::vector<JointInfo> joints;
  std::vector<std::string> joint_names;  // owned copies of joints[j].name

  double position_margin = 0;                                // rad
  Eigen::VectorXd velocity, acceleration;                    // at speed factor 1
  std::map<std::string, std::vector<double>> speed_factors;  // class -> factor per level
  std::vector<std::string> joint_class;                      // per joint

  double start_hold = 0, end_hold = 0, waypoint_dwell = 0, primitive_dwell = 0;

  std::map<std::string, Eigen::VectorXd> postures;                  // the file's postures and their wrist variants
  std::map<std::string, std::string> base_posture;                  // "A'" -> "A", "A" -> "A"
  std::map<std::string, PrimitiveParameters> primitive_parameters;  // by base posture
  std::vector<TrajectorySpec> trajectories;                         // in file order

  int levels() const;  // speed levels per class
};

// Reads and validates the design; throws DataError(file, line, message).
Design read_design(const std::filesystem::path& yaml, const std::vector<JointInfo>& joints);

// The waypoints, moves, dwells and holds of one trajectory (not yet checked against limits).
Trajectory assemble(const Design& design, const TrajectorySpec& spec);

// Throws DataError at the trajectory's line when a joint leaves its position limits less the
// margin, or exceeds its velocity limit, naming the trajectory, the joint and the time.
void check_limits(const Design& design, const TrajectorySpec& spec, const Trajectory& trajectory);

}  // namespace symoro::trajectory
