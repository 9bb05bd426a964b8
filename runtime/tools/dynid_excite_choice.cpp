#include "dynid_excite_choice.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace symoro::dynid {

bool ExcitationTargets::met_by(double k, double p) const { return k < kappa_scaled && p > per_sample; }

std::string ExcitationTargets::missed_by(double k, double p) const {
  std::string out;
  if (!(k < kappa_scaled)) out = fmt::format("scaled kappa {:.4g} is not below {:.4g}", k, kappa_scaled);
  if (!(p > per_sample))
    out += fmt::format("{}logdet/N {:.4g} is not above {:.4g}", out.empty() ? "" : ", ", p, per_sample);
  return out;
}

ExcitationTargets excitation_targets(double kappa_target, const std::vector<ReferenceMeasures>& references) {
  ExcitationTargets t;
  std::string kappa_from, per_sample_from;
  if (kappa_target > 0) t.kappa_scaled = kappa_target, kappa_from = "--kappa-target";
  for (const auto& r : references) {
    if (r.kappa_scaled < t.kappa_scaled) t.kappa_scaled = r.kappa_scaled, kappa_from = r.name;
    if (r.per_sample > t.per_sample) t.per_sample = r.per_sample, per_sample_from = r.name;
  }
  if (!kappa_from.empty()) t.text = fmt::format("scaled kappa below {:.4g} ({})", t.kappa_scaled, kappa_from);
  if (!per_sample_from.empty())
    t.text += fmt::format("{}logdet/N above {:.4g} ({})", t.text.empty() ? "" : ", ", t.per_sample, per_sample_from);
  return t;
}

std::vector<PeriodRung> period_ladder(double first, int harmonics, double longest) {
  const auto tenth = [](double s) { return std::round(s * 10) / 10; };
  std::vector<PeriodRung> out;
  if (first > longest) return {{tenth(longest), harmonics}};
  for (int k = 0; first * std::pow(2.0, k) <= longest + 1e-9; ++k)
    out.push_back({tenth(first * std::pow(2.0, k)), harmonics + static_cast<int>(std::lround(1.5 * k))});
  if (out.back().period < 0.8 * longest) {
    const double doublings = std::log2(longest / first);
    out.push_back({tenth(longest), harmonics + static_cast<int>(std::lround(1.5 * doublings))});
  }
  return out;
}

// The period at which the fundamental, at a joint's velocity limit, sweeps half of its box:
// 2 pi (half width / velocity), the median over the joints, in [5, 60] s to 0.1 s. A slow arm
// (the Kinova's 0.28 rad/s) needs tens of seconds to use its range; a fast one a few.
double auto_period(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, const Eigen::VectorXd& velocity) {
  std::vector<double> t;
  for (Eigen::Index j = 0; j < velocity.size(); ++j)
    t.push_back(2 * 3.14159265358979323846 * (upper(j) - lower(j)) / 4 / velocity(j));
  std::nth_element(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(t.size() / 2), t.end());
  return std::round(std::clamp(t[t.size() / 2], 5.0, 60.0) * 10) / 10;
}

}  // namespace symoro::dynid
