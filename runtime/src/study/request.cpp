// A user's study request into StudyOptions (study/request.hpp).
#include "symoro/study/request.hpp"

#include <cmath>

#include <fmt/format.h>

#include "symoro/study/robot_folder.hpp"
#include "symoro/io/parameters_yaml.hpp"

namespace symoro::study {

namespace {
// The ranges dynid identify's options check (dynid_numbers.hpp), for every caller: a NaN
// interval reached the study from Python and aborted it ("double free or corruption").
void check_range(const char* option, double v, double lo, double hi, bool lo_open, const char* range) {
  if (!(std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi))
    throw StudyRequestError(fmt::format("{} {}: must be {}", option, v, range));
}
void check_count(const char* option, long long v, long long lo, long long hi) {
  if (v < lo || v > hi) throw StudyRequestError(fmt::format("{} {}: must be from {} to {}", option, v, lo, hi));
}
}  // namespace

void check_request(const StudyRequest& r) {
  for (double ms : r.intervals_ms) check_range("--interval", ms, 1, 10000, false, "from 1 to 10000 ms");
  check_count("--trial", r.trial, 1, 1'000'000);
  if (r.threads != 0) check_count("--jobs", r.threads, 1, 1024);  // 0: every core (the default)
  check_range("--rank-timeout", r.rank_timeout, 0, 1e6, true, "> 0 and <= 1e6 s");
  check_range("--torque-delay", r.torque_delay_ms, -1000, 1000, false, "from -1000 to 1000 ms");
  check_count("--clie-iterations", r.clie_iterations, 0, 100000);
  check_range("--clie-std-bound", r.clie_std_bound, 0, 1e6, false, ">= 0 and <= 1e6");
  check_range("--clie-noise-floor", r.clie_noise_floor, 0, 1e6, false, ">= 0 and <= 1e6");
  if (r.validation_ms != 0)
    check_range("--validation-interval", r.validation_ms, 1, 10000, false, "from 1 to 10000 ms");
  check_range("--rescue-prior-weight", r.rescue_prior_weight, 0, 1e6, true, "> 0 and <= 1e6");
  for (double w : r.rescue_prior_weights) check_range("--rescue-prior-weights", w, 0, 1e6, true, "> 0 and <= 1e6");
}

StudyOptions study_options(const StudyRequest& r, const identify::ModelDescription& d,
                           const std::filesystem::path& robot_dir) {
  check_request(r);
  StudyOptions so;
  so.data = r.data;
  so.out = r.out;
  so.trial = r.trial;
  so.threads = r.threads;
  so.fresh = r.fresh;
  so.isolate = !r.in_process;
  so.rank_timeout = r.rank_timeout;
  so.trajectories = r.only;
  so.validation = r.validation;
  if (!r.intervals_ms.empty()) {
    so.intervals.clear();
    for (double ms : r.intervals_ms) so.intervals.push_back(ms / 1000);
  }
  so.least_squares.weighted = r.weighted;
  so.preprocess.torque_delay = r.torque_delay_ms / 1000;
  so.preprocess.use_logged_velocity = r.logged_velocity;
  so.clie.max_iterations = r.clie_iterations;
  so.clie.std_bound = r.clie_std_bound;
  so.clie.noise_floor = r.clie_noise_floor;
  so.projection_metric = projection_metric_from_string(r.projection_metric);
  so.consistency = consistency_from_string(r.consistency);
  so.physical_start = r.physical_start;
  if (r.physical_start && so.consistency != Consistency::physical)
    throw StudyRequestError("--physical-start needs --consistency physical");
  if (r.rescue_metric != "all" && r.rescue_metric != "run")
    throw StudyRequestError("--rescue-metric '" + r.rescue_metric + "' is not one of all, run");
  so.rescue_metric_all_runs = r.rescue_metric == "all";
  so.rescue_prior_weight = r.rescue_prior_weight;
  so.rescue_prior_weights = r.rescue_prior_weights;
  // The rescue's prior: as given, else robot.yaml's nominal parameters when it has them.
  if (r.rescue_prior.empty() || r.rescue_prior == "nominal") {
    std::vector<double> s;
    if (!robot_dir.empty() && nominal_standard_parameters(robot_dir, d.standard, s)) {
      so.rescue_prior = Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size()));
      so.rescue_prior_source = "robot.yaml's nominal parameters";
    } else if (r.rescue_prior == "nominal") {
      throw StudyRequestError(robot_dir.empty() ? std::string("--rescue-prior nominal: no robot folder given")
                                                : (robot_dir / "robot.yaml").string() +
                                                      " has no nominal parameters for --rescue-prior nominal");
    }
  } else if (r.rescue_prior != "zero") {
    std::vector<std::string> names;
    for (const auto& p : d.standard) names.push_back(p.name);
    so.rescue_prior = io::read_parameters_yaml(r.rescue_prior, names);
    so.rescue_prior_source = r.rescue_prior;
  }
  so.validation_interval = r.validation_ms / 1000;
  return so;
}

}  // namespace symoro::study
