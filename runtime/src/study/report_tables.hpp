// The report's Markdown tables (private to report*.cpp): the paper's Tables III-VII, the
// Appendix A record, the cloud dispersion and the final parameters, each computed from a
// StudyResult and returned as a Markdown section with its heading.
#pragma once

#include <string>
#include <vector>

#include "symoro/study/report.hpp"
#include "symoro/report/markdown_table.hpp"
#include "symoro/study/result.hpp"

namespace symoro::study::report_detail {

// --- Text ---------------------------------------------------------------------------------
std::string fixed(double value, int decimals);  // "n/a" when not finite
std::string sig(double value, int digits);      // significant digits, "n/a" when not finite
std::string yes_no(bool value);
long interval_ms(double interval);     // s -> whole ms
double median(std::vector<double> v);  // NaN when empty
using markdown::cell;                  // '|' and newlines made table-safe (md_cell before)

using MarkdownTable = markdown::Table;  // numbers right, the first column and text left

// --- Views of the study -------------------------------------------------------------------
std::vector<double> intervals(const StudyResult& study);  // distinct, ascending
const RunRecord* find_run(const StudyResult& study, const std::string& trajectory, double interval);
const RunRecord* selected_run(const StudyResult& study);  // null when none was selected
std::string family(const std::string& trajectory);        // leading letters: "AG02" -> "AG"
bool is_o_c(const RunRecord& run);                        // OLS -> CLIE
bool is_o_s_c(const RunRecord& run);                      // OLS -> SDP -> CLIE
std::string unit_of(const StudyResult& study, int i);
std::string name_of(const StudyResult& study, int i);

// Dispersion of each stage's cloud at each interval: the trace of the sample covariance of the
// standardized parameters (pca.hpp's cloud_dispersion in the PCA's standardization, else in the
// pooled one of all stages, which the PCA would use).
struct Dispersion {
  double interval = 0;          // s; NaN for all intervals pooled
  double trace[3] = {0, 0, 0};  // OLS, SDP, CLIE (NaN with fewer than two vectors)
  int count[3] = {0, 0, 0};     // vectors used (finite, of the right size)
};
std::vector<Dispersion> dispersion_by_interval(const StudyResult& study);  // last: all pooled

// --- Sections -----------------------------------------------------------------------------
std::string routing_table(const StudyResult& study);                                       // Table III
std::string route_examples_table(const StudyResult& study, const ReportOptions& options);  // IV
std::string transition_table(const StudyResult& study);                                    // Table V
std::string rescue_delta_table(const StudyResult& study, int count = 5);                   // Table VI
std::string validation_table(const StudyResult& study);                                    // Table VII
std::string excitation_section(const StudyResult& study);                                  // report_excitation.cpp
// Every parameter the accepted vector moved from CLIE by more than 3 OLS std while its OLS
// relative std is under 5 %, and the `count` largest such moves (report_moves.cpp).
std::string moves_table(const StudyResult& study, int count = 10);
std::string dispersion_table(const StudyResult& study);
std::string central_runs_table(const StudyResult& study, int count = 5);
std::string appendix_record(const StudyResult& study);
std::string parameter_table(const StudyResult& study);

}  // namespace symoro::study::report_detail
