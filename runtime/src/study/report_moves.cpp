// The report's table of how far each stage moved each parameter of the representative, in units
// of its OLS standard deviation: a stage that moves a parameter the data determine well (small
// relative std) by several standard deviations moves it against the data (issue 30's measure of
// the rescue: no parameter with an OLS relative std under 5 % moved by more than 3 std).
#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "report_tables.hpp"

namespace symoro::study::report_detail {

namespace {
constexpr double kWellDetermined = 0.05;  // OLS std / |OLS| below this
constexpr double kMoveLimit = 3;          // standard deviations

double relative_error(const Eigen::VectorXd& v, const Eigen::VectorXd& truth) {
  return (v - truth).norm() / truth.norm();
}
}  // namespace

std::string moves_table(const StudyResult& study, int count) {
  std::string out = "## Parameter moves in OLS standard deviations";
  const RunRecord* r = selected_run(study);
  out += r ? fmt::format(" ({})\n\n", r->id()) : "\n\n";
  const int np = static_cast<int>(study.names.size());
  if (!r || np == 0 || r->phi_ols.size() != np || r->std_ols.size() != np || r->phi_sdp.size() != np ||
      r->phi_clie.size() != np)
    return out + "No representative with its OLS, SDP and CLIE vectors.\n\n";
  const Eigen::VectorXd& ols = r->phi_ols;
  const Eigen::VectorXd& sd = r->std_ols;
  const Eigen::VectorXd accepted = study.phi_rescue.size() == np ? study.phi_rescue : r->phi_clie;
  auto in_sd = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b, int i) {
    return sd(i) > 0 ? (a(i) - b(i)) / sd(i) : NAN;
  };
  auto well = [&](int i) { return sd(i) < kWellDetermined * std::abs(ols(i)); };
  std::vector<int> order(static_cast<std::size_t>(np));
  std::iota(order.begin(), order.end(), 0);
  auto size = [&](int i) {
    const double m = std::abs(in_sd(accepted, r->phi_clie, i));
    return std::isnan(m) ? -1.0 : m;
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size(a) > size(b); });
  int well_count = 0, moved = 0;
  for (int i = 0; i < np; ++i) {
    well_count += well(i);
    moved += well(i) && size(i) > kMoveLimit;
  }
  const std::string rescue = study.consistency == "physical" ? "physical rescue" : "PD-rescue";
  out += fmt::format(
      "σ: the representative's OLS standard deviation; well determined: σ under {:.0f} % of |OLS| ({} of the {} "
      "parameters). The {} moved {} well-determined parameter{} by more than {:.0f} σ{}.",
      100 * kWellDetermined, well_count, np, study.rescued ? rescue : "accepted vector (no rescue)", moved,
      moved == 1 ? "" : "s", kMoveLimit,
      moved > 0
          ? fmt::format(" (largest: {}, {:+.1f} σ)", name_of(study, order[0]), in_sd(accepted, r->phi_clie, order[0]))
          : "");
  if (study.truth.size() == np && study.truth.norm() > 0)
    out += fmt::format(
        " Relative error against the truth (‖φ − φ_true‖ / ‖φ_true‖): OLS {:.2f} %, SDP {:.2f} %, CLIE {:.2f} %, "
        "accepted {:.2f} %.",
        100 * relative_error(ols, study.truth), 100 * relative_error(r->phi_sdp, study.truth),
        100 * relative_error(r->phi_clie, study.truth), 100 * relative_error(accepted, study.truth));
  out += "\n\n";
  MarkdownTable table({"Parameter", "Unit", "OLS", "σ", "σ / |OLS|", "SDP − OLS [σ]", "CLIE − OLS [σ]",
                       "accepted − CLIE [σ]", "accepted − OLS [σ]", "moved against the data"});
  for (int k = 0; k < np; ++k) {
    const int i = order[static_cast<std::size_t>(k)];
    const bool flagged = well(i) && size(i) > kMoveLimit;
    if (k >= count && !flagged) continue;
    table.row({name_of(study, i), unit_of(study, i), sig(ols(i), 6), sig(sd(i), 3),
               std::abs(ols(i)) > 0 ? fmt::format("{:.1f} %", 100 * sd(i) / std::abs(ols(i))) : "n/a",
               fixed(in_sd(r->phi_sdp, ols, i), 2), fixed(in_sd(r->phi_clie, ols, i), 2),
               fixed(in_sd(accepted, r->phi_clie, i), 2), fixed(in_sd(accepted, ols, i), 2), flagged ? "yes" : ""});
  }
  return out + table.str() + "\n";
}

}  // namespace symoro::study::report_detail
