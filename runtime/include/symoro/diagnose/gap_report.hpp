// The last step of the model-gap workflow: two identification studies of the same robot on the
// same data, one with the model before the diagnosed effects were added and one after, set side
// by side on their held-out validation trajectories (closed-loop simulated torque with each
// study's accepted parameters against the measurement). Markdown with SVG figures.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/study/validation_io.hpp"

namespace symoro::diagnose {

// One held-out trajectory in both studies.
struct GapTrajectory {
  std::string trajectory;
  std::string kind;     // closed-loop or open-loop (the same in both studies)
  double interval = 0;  // s
  int samples = 0;
  double rmse_before = 0, rmse_after = 0;  // N m, accepted parameters, all joints
  Eigen::VectorXd joint_before, joint_after;
};

struct GapComparison {
  std::string robot, before_model, after_model;
  std::vector<GapTrajectory> trajectories;           // those both studies validated, in the before order
  std::vector<std::string> only_before, only_after;  // validated by one study alone (left out)
  // Pooled over the compared trajectories' samples: per joint and over all joints.
  Eigen::VectorXd joint_before, joint_after;
  double rmse_before = 0, rmse_after = 0;
  // Parameters of the after model that the before model does not have (the added effects).
  std::vector<std::string> added;
};

// Throws std::invalid_argument when the studies cannot be compared (other robots, no common
// trajectory, a trajectory validated at different intervals or sample counts).
GapComparison compare_studies(const study::StudyValidation& before, const study::StudyValidation& after);

struct GapReportOptions {
  std::string before_label = "before", after_label = "after";  // e.g. the study folders
  std::string figure_trajectory;   // trajectory whose torques are plotted (default: the last compared)
  std::vector<int> figure_joints;  // 0-based (default: the 3 joints whose error changed most)
};

// The options dynid compare and symoro.compare use: the study folders' names as labels
// ("before" and "after" when a name is empty or both are equal), the plotted trajectory, and
// 1-based joints (std::invalid_argument "joint J is not in 1..n" for one beyond the robot's).
GapReportOptions gap_report_options(const std::filesystem::path& before_dir, const std::filesystem::path& after_dir,
                                    const GapComparison& comparison, const std::string& trajectory,
                                    const std::vector<int>& joints);

// Writes <dir>/gap.md and <dir>/figures/*.svg atomically; returns the files written.
std::vector<std::filesystem::path> write_gap_report(const study::StudyValidation& before,
                                                    const study::StudyValidation& after,
                                                    const GapComparison& comparison, const std::filesystem::path& dir,
                                                    const GapReportOptions& options = {});

}  // namespace symoro::diagnose
