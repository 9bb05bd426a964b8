// The study's report: Markdown with SVG figures reproducing the paper's Tables III-VII, the
// Appendix A record and the figures (PCA clouds, V03 torques), plus the accepted parameters
// with units as YAML and CSV. Everything is written atomically into one folder.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "symoro/study/result.hpp"

namespace symoro::study {

struct ReportOptions {
  std::vector<std::string> examples{"AP01"};  // trajectories compared with the selected one (Table IV)
  std::string validation_figure = "V03";      // trajectory whose torques are plotted
  std::vector<int> figure_joints{1, 3, 5};    // 0-based: J2, J4, J6 as in the paper
};

// Writes <dir>/report.md, <dir>/figures/*.svg, <dir>/parameters.yaml, <dir>/parameters.csv.
// Returns the files written.
std::vector<std::filesystem::path> write_report(const StudyResult& study, const std::filesystem::path& dir,
                                                const ReportOptions& options = {});

// The accepted parameters alone (also written by write_report).
void write_parameters_yaml(const StudyResult& study, const std::filesystem::path& file);
void write_parameters_csv(const StudyResult& study, const std::filesystem::path& file);

}  // namespace symoro::study
