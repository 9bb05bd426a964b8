// dynid trajectories' options: the robot's designed trajectories listed, judged or written as
// reference files.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid_common.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::dynid {

struct TrajectoryOptions {
  std::string out;
  std::vector<std::string> only;
  double period = 0.001;
  bool quality = false;     // print each trajectory's excitation quality (excitation/quality.hpp)
  double interval_ms = 10;  // ... at this sampling interval
  // Logs (symoro-log CSV, e.g. dynid import's) of reference motions rated beside the designed
  // ones: their reference columns when they have them, else their measured motion as the study
  // preprocesses it (a published trajectory's recording).
  std::vector<std::string> compare;
};

// The excitation quality of each trajectory and of all of them together, for the robot's model
// `model` ("" robot.yaml's identified), as a table (compiled once: dynid_trajectories.cpp).
std::string trajectory_quality_table(const Common& common, const std::vector<trajectory::Trajectory>& trajectories,
                                     const TrajectoryOptions& options, const std::string& model = "");

// A stacked regressor W as the table rates it: its triangular factor (W'W = R'R,
// excitation::triangular_factor) and its row count; factors of several motions stack into their whole.
struct RegressorFactor {
  Eigen::MatrixXd R;
  Eigen::Index rows = 0;
  static RegressorFactor of(const Eigen::MatrixXd& W);
  static RegressorFactor stacked(const std::vector<RegressorFactor>& parts);
};

// log det(W'W / N), N the samples (rows / joints): information per sample in the model's SI
// units; -inf when W'W is singular.
double log_det_per_sample(const RegressorFactor& f, int joints);

// The stacked regressor of a designed trajectory sampled at o's period, every o's interval.
Eigen::MatrixXd trajectory_regressor(const identify::IdentificationModel& model, const trajectory::Trajectory& t,
                                     const TrajectoryOptions& options);

// The stacked regressor of a reference log (--compare) at o's interval, as the table rates it;
// `duration` its length, s.
Eigen::MatrixXd reference_regressor(const identify::IdentificationModel& model, const std::string& file,
                                    const TrajectoryOptions& options, double& duration);

void run_trajectories(const Common& common, const TrajectoryOptions& options);

}  // namespace symoro::dynid
