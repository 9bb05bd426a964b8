#include "symoro/study/options.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <stdexcept>

namespace symoro::study {

const char* to_string(ProjectionMetric m) { return m == ProjectionMetric::information ? "information" : "euclidean"; }

ProjectionMetric projection_metric_from_string(const std::string& s) {
  if (s == "euclidean") return ProjectionMetric::euclidean;
  if (s == "information") return ProjectionMetric::information;
  throw std::invalid_argument("projection metric '" + s + "': expected euclidean or information");
}

const char* to_string(Consistency c) { return c == Consistency::physical ? "physical" : "pd"; }

Consistency consistency_from_string(const std::string& s) {
  if (s == "pd") return Consistency::pd;
  if (s == "physical") return Consistency::physical;
  throw std::invalid_argument("consistency '" + s + "': expected pd or physical");
}

std::string StudyOptions::describe() const {
  const auto& p = preprocess;
  const auto& a = audit;
  const auto& c = clie;
  // The physical path's options only when it is on: the PD path's fingerprints stay as they were.
  const std::string physical = consistency == Consistency::physical
                                   ? fmt::format(" | consistency physical {} {} {}", physical_start, physical_clearance,
                                                 physical_rescue_clearance)
                                   : "";
  return fmt::format(
             "pre {} {} {} {} {} {} {} {} {} | ls {} {} | audit {} {} {} {} {} | proj {} {} {} {} {} {} | margins {} | "
             "clie {} {} {} {} {} {} {} {} {} {} {} | metric {} {}",
             p.base_period, p.max_gap, p.filter_order, p.derivative_cutoff, p.anti_alias_fraction, p.drop_stale,
             p.use_logged_velocity, p.torque_delay, p.trim_settling ? "windows-whole edges-trimmed" : "windows-whole",
             least_squares.weighted, least_squares.wls_iterations, a.samples, a.starts, a.seed, a.max_iterations,
             a.tolerance, projection.accept_slack, projection.rescue_floor, projection.max_rounds,
             projection.poses_per_round, projection.weights.size(), projection.shortfall_raise, fmt::join(margins, ","),
             c.max_iterations, c.function_tolerance, c.parameter_tolerance, c.gradient_tolerance, c.bound_factor,
             c.min_bound, c.min_rotor_inertia, c.filter, c.std_bound, c.noise_floor, c.hold_at_bounds,
             to_string(projection_metric), information_ridge) +
         physical;
}

}  // namespace symoro::study
