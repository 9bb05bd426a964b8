// From the momentum observer's residual to collisions: the residual of a whole log, thresholds
// per joint from residuals without contact at a stated false-alarm rate, and the events where a
// joint's residual leaves its band.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/io/log.hpp"
#include "symoro/observer/momentum_observer.hpp"

namespace symoro::observer {

// r at every sample of a log (samples x joints; its first row 0), the observer reset at the
// first sample and stepped by the logged time stamps; the log's measured q, qd and tau as they
// are (no filter: the observer needs no acceleration, and a filter would delay detection). A row
// that repeats the one before (q, qd and tau alike: a stale row) holds r.
Eigen::MatrixXd observe_log(MomentumObserver& observer, const io::Log& log);

struct ThresholdOptions {
  // Expected false alarms per hour of motion, over all joints together, when the residual
  // without contact is as it was in the calibration runs.
  double false_alarms_per_hour = 1;
  // The first samples of each calibration run left out: the residual's own start (r = 0 at the
  // first sample, then the model's error through the filter), 5 time constants.
  double settle_time_constants = 5;
  // The extrapolation's windows, in time constants (0.5 s at K = 50): far longer than r's
  // correlation time, so that their maxima are nearly independent; at least 10 are needed.
  double window_time_constants = 25;
  // The band is never narrower than this times the largest excursion the calibration runs show.
  double peak_margin = 1.25;
};

// Each joint's band: |r - center| <= threshold, by extreme values: the calibration is cut into
// windows, and each joint's largest |r - center| per window gets a Gumbel distribution (fitted
// by its moments); `tail` is the level a window passes with the probability the stated rate
// gives it (rate x window / 3600 / joints). A model's error is not Gaussian and follows the
// motion: its maxima are what a band must cover (measured on a UR5, docs/observer.md: a Gaussian
// tail of the samples raised 8-30x more false alarms on a new motion). threshold = the larger of
// `tail` and peak_margin times the calibration's largest excursion. `tail_alarms` counts the
// events the tail band alone raises on the calibration runs. center and spread: the joint's mean
// and standard deviation.
struct ObserverThresholds {
  Eigen::VectorXd center, spread, tail, peak, threshold;  // per joint; peak: max |r - center|
  double window = 0;                                      // s
  int windows = 0;                                        // in the calibration
  double false_alarms_per_hour = 0, peak_margin = 0;
  double seconds = 0;   // calibration samples' total duration
  int samples = 0;      // calibration samples used
  int tail_alarms = 0;  // events of the tail band alone on the calibration runs
};

ObserverThresholds observer_thresholds(const std::vector<Eigen::MatrixXd>& residuals,
                                       const std::vector<Eigen::VectorXd>& times, const Eigen::VectorXd& gain,
                                       const ThresholdOptions& options = {});

// A span where one joint's residual leaves its band: from the first sample outside to the last
// before it is back inside.
struct CollisionEvent {
  int joint = 0;              // 0-based
  double start = 0, end = 0;  // s, log time
  double peak = 0;            // r - center at the largest |r - center| in the span, N m (N)
  double peak_time = 0;
};

// Every joint's events, in order of start (then joint). A span that starts within `merge_within`
// seconds of the last one's end on the same joint continues it: r crossing its threshold back and
// forth during one contact (or one stretch of model error) is one event, as a user counts them.
// The start, what detection time is, is unchanged by it.
inline constexpr double kMergeWithin = 0.1;  // s: 5 time constants at the default gain
std::vector<CollisionEvent> collision_events(const Eigen::VectorXd& time, const Eigen::MatrixXd& residual,
                                             const ObserverThresholds& thresholds, double merge_within = kMergeWithin);

// thresholds.yaml (what the observer's thresholds are and how they were made) and back; errors
// name the file and the line.
std::string thresholds_yaml(const ObserverThresholds& t, const std::vector<std::string>& joints,
                            const std::string& robot, const std::string& model, const Eigen::VectorXd& gain,
                            const std::string& calibrated_on);
struct ThresholdsFile {
  ObserverThresholds thresholds;
  Eigen::VectorXd gain;
  std::string robot, model;
};
ThresholdsFile read_thresholds_yaml(const std::string& file, const std::vector<std::string>& joints);

}  // namespace symoro::observer
