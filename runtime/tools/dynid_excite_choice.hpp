// dynid excite's choice of the period and the harmonics (issue 41): the first optimized series
// is designed on a ladder of periods, shortest first, until its column-scaled kappa and its log
// det per sample reach the targets (the user's --kappa-target, the reference motions of
// --compare, both strictly beaten); the series after it take the period it was kept at.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::dynid {

// The period at which the fundamental, at a joint's velocity limit, sweeps half of its box:
// 2 pi (half width / velocity), the median over the joints, in [5, 60] s to 0.1 s. A slow arm
// (the Kinova's 0.28 rad/s) needs tens of seconds to use its range; a fast one a few.
double auto_period(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, const Eigen::VectorXd& velocity);

struct ExcitationTargets {
  double kappa_scaled = std::numeric_limits<double>::infinity();  // the series' must be below
  double per_sample = -std::numeric_limits<double>::infinity();   // its log det(W'W / N) above
  std::string text;                                               // what they are and where from
  bool any() const { return !text.empty(); }
  bool met_by(double kappa_scaled, double per_sample) const;
  // What a series with these measures misses ("" when it meets them).
  std::string missed_by(double kappa_scaled, double per_sample) const;
};

// A reference motion's measures, as the quality table rates it.
struct ReferenceMeasures {
  std::string name;
  double kappa_scaled = 0, per_sample = 0;
};

// From --kappa-target (0: none) and the references: below the lowest kappa, above the highest
// log det per sample.
ExcitationTargets excitation_targets(double kappa_target, const std::vector<ReferenceMeasures>& references);

struct PeriodRung {
  double period = 0;  // s
  int harmonics = 0;
};

// The periods tried, shortest first: `first`, doubled while it is at most `longest`, then
// `longest` itself when the last doubling leaves more than a fifth of it unused (to 0.1 s). The
// harmonics grow by 1.5 per doubling (rounded): the same highest frequency at twice the period
// would take twice the harmonics, a problem four times as large for Ipopt, where the slower
// harmonics the longer period adds are what brings the information. `first` beyond `longest`:
// `longest` alone.
std::vector<PeriodRung> period_ladder(double first, int harmonics, double longest);

}  // namespace symoro::dynid
