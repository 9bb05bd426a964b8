// A robot's identification trajectory design (robots/<robot>/trajectories.yaml): postures,
// amplitudes, speed levels and the list of trajectories as primitives (paper, Appendix B).
// Everything the paper leaves open is chosen in that file, so the design is in one place and
// the trajectories are reproducible from it bit for bit.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "symoro/io/log.hpp"
#include "symoro/model_info.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::trajectory {

struct Design;  // defined in design.cpp; opaque to users

class TrajectoryDesign {
 public:
  // Reads and validates the design against the robot's joints (names, count, limits).
  // Throws DataError with file and line.
  static TrajectoryDesign read(const std::filesystem::path& yaml, const std::vector<JointInfo>& joints);

  // Trajectory names in file order (e.g. PA01 ... V03).
  std::vector<std::string> names() const;
  // Builds one trajectory; throws DataError for an unknown name or a trajectory that leaves
  // the joint position or velocity limits (naming the trajectory, joint and time).
  Trajectory build(const std::string& name) const;
  std::vector<Trajectory> build_all() const;

  const std::filesystem::path& path() const;
  ~TrajectoryDesign();
  TrajectoryDesign(TrajectoryDesign&&) noexcept;
  TrajectoryDesign& operator=(TrajectoryDesign&&) noexcept;

 private:
  TrajectoryDesign();
  std::unique_ptr<Design> d_;
};

// The trajectory sampled every `period` seconds from 0 to its duration (inclusive), as a
// reference file (io::Log with source "reference": time, q_ref, qd_ref, qdd_ref).
io::Log reference_log(const Trajectory& t, double period, const std::string& robot,
                      const std::vector<std::string>& joint_names);

}  // namespace symoro::trajectory
