// What a user asks of a study, in the words of dynid identify's options and symoro.identify's
// keywords (milliseconds, names, a prior named or in a file), and the one translation of it into
// StudyOptions for both: the same defaults (StudyOptions' own), the same checks, the same errors.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "symoro/identify/identification_model.hpp"
#include "symoro/study/options.hpp"

namespace symoro::study {

struct StudyRequest {
  std::string data, out;                      // the dataset and the study folder
  std::vector<double> intervals_ms;           // empty: StudyOptions' (the paper's)
  std::vector<std::string> only, validation;  // empty: every family but V; family V
  int threads = StudyOptions{}.threads;
  int trial = StudyOptions{}.trial;
  bool weighted = false, fresh = false;
  bool in_process = !StudyOptions{}.isolate;
  bool physical_start = StudyOptions{}.physical_start;
  int clie_iterations = StudyOptions{}.clie.max_iterations;
  double clie_std_bound = StudyOptions{}.clie.std_bound;
  double clie_noise_floor = StudyOptions{}.clie.noise_floor;
  double validation_ms = StudyOptions{}.validation_interval * 1000;  // 0: the selected run's interval
  double torque_delay_ms = StudyOptions{}.preprocess.torque_delay * 1000;
  // Fit on the log's own velocity column instead of q's zero-phase derivative (a robot whose
  // controller estimates qd better than its encoder's q differentiates, e.g. a Franka's dq).
  bool logged_velocity = StudyOptions{}.preprocess.use_logged_velocity;
  double rank_timeout = StudyOptions{}.rank_timeout;
  std::string projection_metric = to_string(StudyOptions{}.projection_metric);
  std::string consistency = to_string(StudyOptions{}.consistency);
  std::string rescue_metric = StudyOptions{}.rescue_metric_all_runs ? "all" : "run";
  // "": robot.yaml's nominal parameters when it has them, else none; "nominal" (required),
  // "zero", or a standard-parameter YAML file.
  std::string rescue_prior;
  double rescue_prior_weight = StudyOptions{}.rescue_prior_weight;
  std::vector<double> rescue_prior_weights;  // chosen among by held-out error when given
};

// A request that cannot be met (an option another needs, a prior robot.yaml does not have):
// dynid's usage errors, Python's ValueError. Named in dynid's options.
struct StudyRequestError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Every number of the request within dynid identify's ranges (finite, intervals 1-10000 ms,
// jobs 1-1024, ...); StudyRequestError naming the option and the value otherwise. study_options
// calls it first.
void check_request(const StudyRequest& request);

// The study's options for `model`; robot_dir: the robot folder whose robot.yaml holds the
// nominal parameters (empty: none). The progress and stop callbacks are the caller's to set.
StudyOptions study_options(const StudyRequest& request, const identify::ModelDescription& model,
                           const std::filesystem::path& robot_dir);

}  // namespace symoro::study
