// The paper's findings (crane-x7-identification-paper.tex, Sec. VI, Tables III-VII, Appendix A)
// next to what a study found, each computed from the StudyResult: the report's "Reproduction"
// section and the tests that hold the study to them.
#pragma once

#include <string>
#include <vector>

#include "symoro/study/result.hpp"

namespace symoro::study {

struct Finding {
  std::string name;   // e.g. "clouds contract OLS → SDP → CLIE"
  std::string paper;  // the paper's value, as it reports it
  std::string study;  // this study's value
  // "reproduced", "not reproduced", "differs" (a value, not a claim: e.g. another representative)
  // or "n/a" (the study has nothing to compare).
  std::string verdict;
  std::string note;  // how it is measured, or why it cannot be
};

// The numbers behind the findings, for tests and the report.
struct FindingValues {
  // Cloud dispersion tr Sigma_z (pca.hpp's standardization) of OLS, SDP and CLIE over all runs
  // and at the representative's interval (NaN where a cloud has fewer than two vectors).
  double all[3], at_selected[3];
  double selected_interval = 0;  // s (0 when none was selected)
  // Mean validation RMSE (N m) of the representative's final (CLIE) and accepted vectors over
  // the validation trajectories; NaN when there is none.
  double rmse_final = 0, rmse_accepted = 0;
  int validations = 0, validations_finite = 0, validations_closed_loop = 0;
  int clie_ran = 0, clie_pd = 0;                          // runs whose CLIE ran; of those, PD after CLIE
  std::vector<int> pd_ols;                                // per interval (ascending): runs whose OLS estimate was PD
  std::vector<int> runs;                                  // per interval: runs not failed
  std::vector<double> intervals;                          // s, ascending
  double kappa_median = 0, kappa_min = 0, kappa_max = 0;  // raw, over the runs
  double kappa_scaled_median = 0, kappa_scaled_min = 0, kappa_scaled_max = 0;
};

FindingValues finding_values(const StudyResult& study);
std::vector<Finding> paper_findings(const StudyResult& study);

}  // namespace symoro::study
