// Shared by the report's tests (test_identify_report.cpp, test_identify_report_figures.cpp): a
// synthetic StudyResult with known routes, rescue deltas and validation, the report written once
// per test program (fixture Report), and readers of its Markdown tables and SVG figures.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <regex>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "symoro/study/report.hpp"
#include "symoro/study/reproduction.hpp"
#include "symoro/report/svg_plot.hpp"
#include "svg_test_support.hpp"

namespace symoro::test::report {

using namespace symoro::study;
namespace fs = std::filesystem;
using symoro::test::panels;
using symoro::test::tick_values;

inline constexpr int np = 8;
inline const std::vector<std::string> kTrajectories{"PC07", "AG02", "PA01", "AP01", "PB03"};
inline const std::vector<double> kIntervals{0.08, 0.01, 0.04, 0.02};  // unsorted on purpose

// --- Helpers ------------------------------------------------------------------------------

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
  return n;
}

inline std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

inline std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// The Markdown table following the first heading that starts with `heading`: header row first,
// the alignment row dropped.
inline std::vector<std::vector<std::string>> md_table(const std::string& md, const std::string& heading) {
  std::vector<std::vector<std::string>> rows;
  auto pos = md.find("\n" + heading);
  if (pos == std::string::npos) return rows;
  std::istringstream in(md.substr(pos + 1));
  std::string line;
  std::getline(in, line);  // the heading
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.rfind("|", 0) != 0) {
      if (inside || line.rfind("#", 0) == 0) break;
      continue;
    }
    inside = true;
    if (line.rfind("|:---", 0) == 0) continue;
    std::vector<std::string> cells;
    std::string cell;
    for (std::size_t i = 1; i < line.size(); ++i) {
      if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
        cell += '|';
        ++i;
      } else if (line[i] == '|') {
        cells.push_back(trim(cell));
        cell.clear();
      } else {
        cell += line[i];
      }
    }
    rows.push_back(cells);
  }
  return rows;
}

inline int column(const std::vector<std::vector<std::string>>& table, const std::string& name) {
  const auto& h = table.at(0);
  const auto it = std::find(h.begin(), h.end(), name);
  EXPECT_NE(it, h.end()) << "no column " << name;
  return static_cast<int>(it - h.begin());
}

// Tags balance: every opened element is closed in order (comments, declarations and
// self-closing tags aside), and no text holds a raw '<'.
inline bool balanced(const std::string& svg) {
  std::vector<std::string> open;
  std::size_t pos = 0;
  while ((pos = svg.find('<', pos)) != std::string::npos) {
    const auto end = svg.find('>', pos);
    if (end == std::string::npos) return false;
    const std::string tag = svg.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;
    if (tag.find('<') != std::string::npos) return false;
    if (tag.back() == '/') continue;
    const std::string name = tag.substr(tag[0] == '/' ? 1 : 0, tag.find_first_of(" \n") - (tag[0] == '/' ? 1 : 0));
    if (tag[0] == '/') {
      if (open.empty() || open.back() != name) return false;
      open.pop_back();
    } else {
      open.push_back(name);
    }
  }
  return open.empty();
}

// The text of every <text class="cls" ...>value</text>, as numbers.
inline long ms(double interval) { return std::lround(interval * 1000); }

// --- The synthetic study --------------------------------------------------------------------

struct Synthetic {
  StudyResult study;
  int selected = -1, failed = -1;
  Eigen::VectorXd delta;  // phi_rescue - phi_clie of the selected run
};

// Routes as the paper's Table IV for AP01 and AG02, a fixed pattern for the others.
inline std::string route_of(const std::string& t, long interval_ms) {
  if (t == "AG02") return interval_ms == 80 ? "O-C" : "O-S-C";
  if (t == "AP01") return interval_ms == 10 ? "O-S-C" : "O-C";
  if (t == "PC07") return "O-S-C";
  if (t == "PA01") return interval_ms <= 20 ? "O-S-C" : "O-C";
  return interval_ms == 40 ? "O-S-C" : "O-C";
}

inline Synthetic make_study() {
  Synthetic s;
  StudyResult& st = s.study;
  st.robot = "crane_x7";
  st.model = "reduced";
  st.data_source = "synthetic test";
  st.names = {"ZZR1", "XXR2", "ZZR2", "MX2", "MYR2", "IA3", "FV1", "FV2"};
  st.units = {"kg*m^2", "kg*m^2", "kg*m^2", "kg*m", "kg*m", "kg*m^2", "N*m*s/rad", "N*m*s/rad"};
  Eigen::VectorXd truth(np);
  truth << 0.0118, 0.0588, 0.0904, 0.00712, -0.238, 0.00713, 0.0736, 0.317;
  st.truth = truth;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 1);
  auto around = [&](double sd) {
    Eigen::VectorXd v(np);
    for (int i = 0; i < np; ++i) v(i) = truth(i) + sd * noise(rng);
    return v;
  };
  for (double interval : kIntervals)
    for (std::size_t k = 0; k < kTrajectories.size(); ++k) {
      RunRecord r;
      r.trajectory = kTrajectories[k];
      r.interval = interval;
      r.samples = static_cast<int>(std::lround(30 / interval));
      r.kappa = 30 + 10.0 * static_cast<double>(k) + interval * 100;
      r.kappa_scaled = r.kappa / 3;
      r.route = route_of(r.trajectory, ms(interval));
      r.ols_pd = r.route == "O-C";
      r.ols_lambda_min = r.ols_pd ? 1e-4 : -2e-4;
      r.eps = r.route == "O-S-C" ? 0.001 * static_cast<double>(1 + k % 3) : 0;
      r.phi_ols = around(0.01);
      r.std_ols = Eigen::VectorXd::Constant(np, 0.002);
      r.phi_sdp = r.route == "O-C" ? r.phi_ols : around(0.005);
      r.phi_clie = around(0.001);
      r.clie_success = true;
      r.clie_termination = "CONVERGENCE";
      r.clie_cost_initial = 2;
      r.clie_cost_final = 0.5;
      r.clie_iterations = 12;
      r.clie_pd = k % 2 == 0;
      r.clie_lambda_min = r.clie_pd ? 5e-5 : -1e-5;
      r.t_ols = 0.1, r.t_audit = 1, r.t_sdp = r.route == "O-S-C" ? 2 : 0, r.t_clie = 100 + static_cast<double>(k);
      st.runs.push_back(r);
    }
  const int n = static_cast<int>(st.runs.size());
  for (int i = 0; i < n; ++i) {
    if (st.runs[i].id() == "AG02@40ms") s.selected = i;
    if (st.runs[i].id() == "PB03@20ms") s.failed = i;
  }
  RunRecord& f = st.runs[s.failed];
  f.clie_success = false;
  f.clie_termination = "NO_CONVERGENCE: simulation diverged at t = 3.2 s";
  f.phi_clie.resize(0);
  f.clie_pd = false;

  // PCA scores known in closed form; the failed run has no CLIE score.
  st.pca.mean = truth;
  st.pca.scale = Eigen::VectorXd::Constant(np, 0.01);
  st.pca.components = Eigen::MatrixXd::Identity(np, 2);
  st.pca.explained = Eigen::Vector2d(0.6, 0.25);
  st.pca.ols.resize(n, 2);
  for (int i = 0; i < n; ++i) st.pca.ols.row(i) << 3 * std::cos(i), 2 * std::sin(i) - 0.5;
  st.pca.sdp = 0.5 * st.pca.ols;
  st.pca.clie = 0.2 * st.pca.ols;
  st.pca.clie.row(s.failed).setConstant(std::numeric_limits<double>::quiet_NaN());
  st.selection.run = s.selected;
  st.selection.components = 2;
  st.selection.rule = "smallest Mahalanobis distance to the CLIE cloud's centre";
  for (int i = 0; i < n; ++i) st.selection.centrality.push_back(i == s.selected ? 0.1 : 1.0 + i);

  s.delta.resize(np);
  s.delta << 1e-4, -3e-5, 2.5e-4, 0, -1.1e-4, 7e-5, -2e-4, 5e-6;
  st.phi_rescue = st.runs[s.selected].phi_clie + s.delta;
  st.rescued = true;
  st.rescue_eps = 0;
  st.final_lambda_min = 3.0000000000000001e-6;
  st.final_worst_pose = Eigen::VectorXd::Constant(7, 0.5);
  st.accepted = true;

  const double rmse[3][4] = {
      {0.16761, 0.16729, 0.07726, 0.07709}, {0.17057, 0.17032, 0.08814, 0.08805}, {0.16642, 0.16630, 0.06721, 0.06719}};
  for (int v = 0; v < 3; ++v) {
    ValidationRecord rec;
    rec.trajectory = "V0" + std::to_string(v + 1);
    rec.interval = 0.04;
    rec.rmse_clie = rmse[v][0], rec.rmse_rescue = rmse[v][1], rec.mne_clie = rmse[v][2], rec.mne_rescue = rmse[v][3];
    rec.rmse_joint_clie = Eigen::VectorXd::Constant(7, 0.1);
    rec.rmse_joint_rescue = Eigen::VectorXd::Constant(7, 0.09);
    if (v == 2) {
      const int samples = 50;
      rec.time = Eigen::VectorXd::LinSpaced(samples, 0, 0.04 * (samples - 1));
      rec.tau_measured.resize(samples, 7);
      for (int i = 0; i < samples; ++i)
        for (int j = 0; j < 7; ++j) rec.tau_measured(i, j) = (j + 1) * std::sin(rec.time(i) + j);
      rec.tau_clie = rec.tau_measured.array() + 0.05;
      rec.tau_rescue = rec.tau_measured.array() - 0.05;
    }
    st.validation.push_back(rec);
  }
  st.threads = 4;
  st.wall = 1234.5;
  st.wall_runs = 4321;
  return s;
}

inline fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("symoro_report_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

class Report : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synthetic_ = new Synthetic(make_study());
    dir_ = new fs::path(fresh_dir("full"));
    written_ = new std::vector<fs::path>(write_report(synthetic_->study, *dir_));
    md_ = new std::string(read_text(*dir_ / "report.md"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete synthetic_;
    delete dir_;
    delete written_;
    delete md_;
  }
  static const StudyResult& study() { return synthetic_->study; }
  inline static Synthetic* synthetic_ = nullptr;
  inline static fs::path* dir_ = nullptr;
  inline static std::vector<fs::path>* written_ = nullptr;
  inline static std::string* md_ = nullptr;
};

}  // namespace symoro::test::report
