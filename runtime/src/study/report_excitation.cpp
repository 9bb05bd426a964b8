// The report's excitation section: how well each family of identification trajectories tells
// the base parameters apart (excitation/quality.hpp), structured and optimized side by side.
#include <algorithm>
#include <map>

#include <fmt/format.h>

#include "report_tables.hpp"

namespace symoro::study::report_detail {

std::string excitation_section(const StudyResult& study) {
  std::string out = "## Excitation of the identification trajectories\n\n";
  if (study.runs.empty()) return out + "No runs.\n\n";
  const RunRecord* sel = selected_run(study);
  const double interval = sel ? sel->interval : intervals(study).front();
  out += fmt::format(
      "At {} ms (the representative's interval): κ of W (the paper's), κ with unit columns, and log det of W'W with "
      "unit columns (at most 0, reached by orthogonal columns; it measures how well a motion tells the parameters "
      "apart, whatever its length or units), medians per family; the family's best trajectory (smallest scaled κ) "
      "and its weakest direction (the smallest scaled singular value's largest parameters). Optimized trajectories "
      "(`dynid excite`, family OF) stand next to the structured families; docs/excitation.md compares the two over "
      "repeated trials.\n\n",
      interval_ms(interval));
  std::map<std::string, std::vector<const RunRecord*>> by_family;
  for (const RunRecord& r : study.runs)
    if (!r.failed && r.interval == interval) by_family[family(r.trajectory)].push_back(&r);
  MarkdownTable table(
      {"Family", "Trajectories", "κ", "κ scaled", "log det", "Best", "its κ scaled", "its weakest direction"});
  for (const auto& [fam, runs] : by_family) {
    std::vector<double> kappa, scaled, log_det;
    const RunRecord* best = runs.front();
    for (const RunRecord* r : runs) {
      kappa.push_back(r->kappa);
      scaled.push_back(r->kappa_scaled);
      log_det.push_back(r->log_det_scaled);
      if (r->kappa_scaled < best->kappa_scaled) best = r;
    }
    table.row({fam, std::to_string(runs.size()), sig(median(kappa), 4), sig(median(scaled), 4),
               fixed(median(log_det), 2), best->trajectory, sig(best->kappa_scaled, 4), cell(best->weakest)});
  }
  return out + table.str() + "\n";
}

}  // namespace symoro::study::report_detail
