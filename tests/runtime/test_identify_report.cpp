// The study report: its numbers against independent computations from a synthetic StudyResult
// (routing counts, route examples, rescue deltas, validation means, cloud dispersion, Appendix A
// order), the parameter files read back exactly (yaml-cpp, CSV), the SVG figures checked for
// balanced tags, one marker per plotted point and ticks covering the data, graceful output for
// missing data, and the SVG module's nice ticks against hand values.
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

#include "symoro/identify/report.hpp"
#include "symoro/identify/reproduction.hpp"
#include "symoro/identify/svg_plot.hpp"

namespace {

using namespace symoro::identify;
namespace fs = std::filesystem;

constexpr int np = 8;
const std::vector<std::string> kTrajectories{"PC07", "AG02", "PA01", "AP01", "PB03"};
const std::vector<double> kIntervals{0.08, 0.01, 0.04, 0.02};  // unsorted on purpose

// --- Helpers ------------------------------------------------------------------------------

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
  return n;
}

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// The Markdown table following the first heading that starts with `heading`: header row first,
// the alignment row dropped.
std::vector<std::vector<std::string>> md_table(const std::string& md, const std::string& heading) {
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

int column(const std::vector<std::vector<std::string>>& table, const std::string& name) {
  const auto& h = table.at(0);
  const auto it = std::find(h.begin(), h.end(), name);
  EXPECT_NE(it, h.end()) << "no column " << name;
  return static_cast<int>(it - h.begin());
}

// Tags balance: every opened element is closed in order (comments, declarations and
// self-closing tags aside), and no text holds a raw '<'.
bool balanced(const std::string& svg) {
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
std::vector<double> tick_values(const std::string& svg, const std::string& cls) {
  std::vector<double> v;
  const std::regex re("<text class=\"" + cls + "\"[^>]*>([^<]*)</text>");
  for (std::sregex_iterator it(svg.begin(), svg.end(), re), end; it != end; ++it) v.push_back(std::stod((*it)[1]));
  return v;
}

std::vector<std::string> panels(const std::string& svg) {
  std::vector<std::string> out;
  const std::string open = "<g class=\"panel\">";
  for (auto pos = svg.find(open); pos != std::string::npos;) {
    const auto next = svg.find(open, pos + 1);
    out.push_back(svg.substr(pos, next == std::string::npos ? std::string::npos : next - pos));
    pos = next;
  }
  return out;
}

long ms(double interval) { return std::lround(interval * 1000); }

// --- The synthetic study --------------------------------------------------------------------

struct Synthetic {
  StudyResult study;
  int selected = -1, failed = -1;
  Eigen::VectorXd delta;  // phi_rescue - phi_clie of the selected run
};

// Routes as the paper's Table IV for AP01 and AG02, a fixed pattern for the others.
std::string route_of(const std::string& t, long interval_ms) {
  if (t == "AG02") return interval_ms == 80 ? "O-C" : "O-S-C";
  if (t == "AP01") return interval_ms == 10 ? "O-S-C" : "O-C";
  if (t == "PC07") return "O-S-C";
  if (t == "PA01") return interval_ms <= 20 ? "O-S-C" : "O-C";
  return interval_ms == 40 ? "O-S-C" : "O-C";
}

Synthetic make_study() {
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

  const double rmse[3][4] = {{0.16761, 0.16729, 0.07726, 0.07709},
                             {0.17057, 0.17032, 0.08814, 0.08805},
                             {0.16642, 0.16630, 0.06721, 0.06719}};
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

fs::path fresh_dir(const std::string& name) {
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
  static Synthetic* synthetic_;
  static fs::path* dir_;
  static std::vector<fs::path>* written_;
  static std::string* md_;
};
Synthetic* Report::synthetic_ = nullptr;
fs::path* Report::dir_ = nullptr;
std::vector<fs::path>* Report::written_ = nullptr;
std::string* Report::md_ = nullptr;

// --- Nice ticks -----------------------------------------------------------------------------

TEST(SvgPlot, NiceTicksMatchHandValues) {
  auto expect = [](double lo, double hi, int n, double step, int decimals, std::vector<double> values) {
    const svg::Ticks t = svg::nice_ticks(lo, hi, n);
    EXPECT_DOUBLE_EQ(t.step, step) << lo << " " << hi;
    EXPECT_EQ(t.decimals, decimals) << lo << " " << hi;
    ASSERT_EQ(t.values.size(), values.size()) << lo << " " << hi;
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_DOUBLE_EQ(t.values[i], values[i]) << lo << " " << hi;
  };
  expect(0, 10, 5, 2, 0, {0, 2, 4, 6, 8, 10});
  expect(-3.2, 7.9, 5, 2, 0, {-4, -2, 0, 2, 4, 6, 8});                          // raw 2.22 -> 2
  expect(0.013, 0.087, 5, 0.01, 2, {0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09});
  expect(120, 980, 4, 200, 0, {0, 200, 400, 600, 800, 1000});                 // raw 215 -> 200
  expect(-1e-4, 3e-4, 5, 1e-4, 4, {-1e-4, 0, 1e-4, 2e-4, 3e-4});              // raw 8e-5 -> 1e-4
  expect(0.3, 0.7, 4, 0.1, 1, {0.3, 0.4, 0.5, 0.6, 0.7});                     // 0.3/0.1 is 2.99..96
  expect(7.9, -3.2, 5, 2, 0, {-4, -2, 0, 2, 4, 6, 8});                         // reversed bounds
  // Exactly representable: 0.3 must be the double nearest 0.3, not 3 * 0.1.
  EXPECT_EQ(svg::nice_ticks(0.3, 0.7, 4).values[0], 0.3);
}

TEST(SvgPlot, DegenerateRangesStillCoverTheValue) {
  for (double v : {5.0, 0.0, -1e-5, 1e6}) {
    const svg::Ticks t = svg::nice_ticks(v, v, 5);
    ASSERT_GE(t.values.size(), 2u) << v;
    EXPECT_LE(t.values.front(), v);
    EXPECT_GE(t.values.back(), v);
    EXPECT_GT(t.step, 0);
  }
  const svg::Ticks t = svg::nice_ticks(std::nan(""), 1, 5);
  EXPECT_DOUBLE_EQ(t.values.front(), 0);
  EXPECT_DOUBLE_EQ(t.values.back(), 1);
}

TEST(SvgPlot, TickTextNeverShowsMinusZero) {
  EXPECT_EQ(svg::tick_text(-1e-17, 2), "0.00");
  EXPECT_EQ(svg::tick_text(-0.0, 0), "0");
  EXPECT_EQ(svg::tick_text(-0.25, 2), "-0.25");
  EXPECT_EQ(svg::tick_text(1000, 0), "1000");
}

TEST(SvgPlot, RendersOneMarkerPerFinitePointAndEscapesText) {
  svg::Figure f;
  f.title = "a <b> & \"c\"";
  svg::Panel p;
  svg::Series s;
  s.name = "pts";
  s.x = {0, 1, 2, std::nan(""), 4};
  s.y = {1, -2, 3, 4, 100};
  for (auto m : {svg::Marker::circle, svg::Marker::square, svg::Marker::triangle, svg::Marker::diamond,
                 svg::Marker::cross}) {
    s.style.marker = m;
    p.points.push_back(s);
  }
  svg::Series line;
  line.x = {0, 1, std::nan(""), 3, 4};
  line.y = {0, 1, 2, 3, 4};
  p.lines.push_back(line);
  p.labels.push_back({4, 100, "x<y", true, "#000"});
  f.panels = {p, p};
  const std::string out = svg::render(f);
  EXPECT_TRUE(balanced(out));
  EXPECT_EQ(count(out, "class=\"marker\""), 2u * 5 * 4);   // NaN pair left out
  EXPECT_EQ(count(out, "class=\"legend-marker\""), 1u);    // one entry per name
  EXPECT_EQ(count(out, "<polyline"), 2u * 2);              // the NaN breaks the line
  EXPECT_EQ(count(out, "class=\"ring\""), 2u);
  EXPECT_NE(out.find("a &lt;b&gt; &amp; &quot;c&quot;"), std::string::npos);
  EXPECT_NE(out.find(">x&lt;y</text>"), std::string::npos);
  for (const auto& panel : panels(out)) {
    const auto xt = tick_values(panel, "xtick"), yt = tick_values(panel, "ytick");
    ASSERT_FALSE(xt.empty());
    EXPECT_LE(xt.front(), 0);
    EXPECT_GE(xt.back(), 4);
    EXPECT_LE(*std::min_element(yt.begin(), yt.end()), -2);
    EXPECT_GE(*std::max_element(yt.begin(), yt.end()), 100);
  }
}

// --- The report -----------------------------------------------------------------------------

TEST_F(Report, WritesEveryFileAtomicallyAndReturnsThem) {
  const std::vector<fs::path> expected{*dir_ / "figures" / "routing.svg", *dir_ / "figures" / "pca_clouds.svg",
                                       *dir_ / "figures" / "validation_V03.svg", *dir_ / "report.md",
                                       *dir_ / "parameters.yaml", *dir_ / "parameters.csv"};
  EXPECT_EQ(*written_, expected);
  for (const auto& p : expected) EXPECT_TRUE(fs::is_regular_file(p)) << p;
  // No temporary file left behind.
  for (const auto& dir : {*dir_, *dir_ / "figures"})
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
  for (const char* fig : {"figures/routing.svg", "figures/pca_clouds.svg", "figures/validation_V03.svg"})
    EXPECT_NE(md_->find(std::string("](") + fig + ")"), std::string::npos) << fig;
  EXPECT_NE(md_->find("# Identification report: crane_x7 (reduced)"), std::string::npos);
  EXPECT_NE(md_->find("Data source: synthetic test"), std::string::npos);
  EXPECT_NE(md_->find("**Accepted model**: AG02@40ms, PD-rescued"), std::string::npos);
  EXPECT_NE(md_->find("[28.6, 28.6, 28.6, 28.6, 28.6, 28.6, 28.6] deg"), std::string::npos);  // 0.5 rad
}

TEST_F(Report, TableIIICountsTheRecordsRoutes) {
  const auto t = md_table(*md_, "## Table III");
  ASSERT_EQ(t.size(), 1 + kIntervals.size() + 1);
  const int oc = column(t, "PD-OLS → CLIE"), osc = column(t, "NPD-OLS → SDP → CLIE"), total = column(t, "Total");
  const int converged = column(t, "CLIE converged"), pd = column(t, "CLIE PD");
  std::vector<double> sorted = kIntervals;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k <= sorted.size(); ++k) {
    const bool all = k == sorted.size();
    int n_oc = 0, n_osc = 0, n = 0, n_conv = 0, n_pd = 0;
    for (const auto& r : study().runs)
      if (all || ms(r.interval) == ms(sorted[k])) {
        ++n;
        n_oc += r.route == "O-C";
        n_osc += r.route == "O-S-C";
        n_conv += r.clie_success;
        n_pd += r.clie_pd;
      }
    const auto& row = t[k + 1];
    EXPECT_EQ(row[0], all ? "All" : std::to_string(ms(sorted[k])));
    EXPECT_EQ(std::stoi(row[oc]), n_oc) << row[0];
    EXPECT_EQ(std::stoi(row[osc]), n_osc) << row[0];
    EXPECT_EQ(std::stoi(row[total]), n) << row[0];
    EXPECT_EQ(std::stoi(row[converged]), n_conv) << row[0];
    EXPECT_EQ(std::stoi(row[pd]), n_pd) << row[0];
  }
  // The paper's routes for AG02: O-S-C at 10, 20, 40 ms.
  EXPECT_EQ(std::stoi(t[1][osc]), 4);  // 10 ms: AG02, AP01, PA01, PC07
}

TEST_F(Report, TableIVShowsTheExampleAndTheRepresentative) {
  const auto t = md_table(*md_, "## Table IV");
  ASSERT_EQ(t.size(), 5u);
  for (const std::string traj : {"AP01", "AG02"}) {
    const int kappa = column(t, traj + " κ"), route = column(t, traj + " route"), eps = column(t, traj + " ε_PD");
    for (std::size_t k = 1; k < t.size(); ++k) {
      const RunRecord* r = nullptr;
      for (const auto& run : study().runs)
        if (run.trajectory == traj && std::to_string(ms(run.interval)) == t[k][0]) r = &run;
      ASSERT_NE(r, nullptr) << traj << " " << t[k][0];
      EXPECT_NEAR(std::stod(t[k][kappa]), r->kappa, 0.05);
      EXPECT_EQ(t[k][route], r->route);
      if (r->route == "O-C")
        EXPECT_EQ(t[k][eps], "--");
      else
        EXPECT_NEAR(std::stod(t[k][eps]), r->eps, 1e-12);
    }
  }
}

TEST_F(Report, TableVFollowsTheRepresentativesStages) {
  const auto t = md_table(*md_, "## Table V");
  ASSERT_EQ(t.size(), 5u);
  const RunRecord& r = study().runs[synthetic_->selected];
  EXPECT_NE(md_->find("## Table V: stage-wise evolution of the representative AG02@40ms"), std::string::npos);
  EXPECT_EQ(t[1][0], "OLS");
  EXPECT_EQ(t[1][1], r.ols_pd ? "yes" : "no");
  EXPECT_EQ(t[2][0], "SDP");
  EXPECT_EQ(t[2][2], "O-S-C");
  EXPECT_DOUBLE_EQ(std::stod(t[2][3]), r.eps);
  EXPECT_EQ(t[3][0], "CLIE");
  EXPECT_EQ(t[3][1], "no");
  EXPECT_EQ(t[4][0], "PD-rescue");
  EXPECT_EQ(t[4][1], "yes");
  EXPECT_DOUBLE_EQ(std::stod(t[4][3]), 0);
}

TEST_F(Report, TableVIListsTheFiveLargestChangesInOrder) {
  const auto t = md_table(*md_, "## Table VI");
  ASSERT_EQ(t.size(), 6u);
  const Eigen::VectorXd d = study().phi_rescue - study().runs[synthetic_->selected].phi_clie;
  std::vector<int> idx(np);
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) { return std::abs(d(a)) > std::abs(d(b)); });
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(t[k + 1][0], study().names[idx[k]]);
    EXPECT_EQ(t[k + 1][1], study().units[idx[k]]);
    EXPECT_NEAR(std::stod(t[k + 1][4]), d(idx[k]), 1e-3 * std::abs(d(idx[k])));
  }
  EXPECT_EQ(t[1][0], "ZZR2");  // delta 2.5e-4, by construction the largest
}

TEST_F(Report, TableVIIMeanIsTheMeanOfTheRecords) {
  const auto t = md_table(*md_, "## Table VII");
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[4][0], "Mean");
  const auto& v = study().validation;
  const double means[4] = {(v[0].rmse_clie + v[1].rmse_clie + v[2].rmse_clie) / 3,
                           (v[0].rmse_rescue + v[1].rmse_rescue + v[2].rmse_rescue) / 3,
                           (v[0].mne_clie + v[1].mne_clie + v[2].mne_clie) / 3,
                           (v[0].mne_rescue + v[1].mne_rescue + v[2].mne_rescue) / 3};
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(std::stod(t[4][3 + k]), means[k], 1e-5 * means[k]);
  // The paper's means, which these records reproduce.
  EXPECT_NEAR(std::stod(t[4][3]), 0.16820, 5e-6);
  EXPECT_NEAR(std::stod(t[4][6]), 0.07744, 5e-6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(std::stod(t[k + 1][3]), v[k].rmse_clie);
    EXPECT_EQ(t[k + 1][2], v[k].kind);  // closed-loop, as the paper's
  }
}

TEST_F(Report, DispersionIsTheTraceOfTheStandardizedCovariance) {
  const auto t = md_table(*md_, "### Cloud dispersion");
  ASSERT_EQ(t.size(), 1 + kIntervals.size() + 1);
  auto trace = [&](long interval, int stage, int& n) {
    std::vector<Eigen::VectorXd> z;
    for (const auto& r : study().runs) {
      const Eigen::VectorXd& phi = stage == 0 ? r.phi_ols : stage == 1 ? r.phi_sdp : r.phi_clie;
      if ((interval < 0 || ms(r.interval) == interval) && phi.size() == np)
        z.push_back(((phi - study().pca.mean).array() / study().pca.scale.array()).matrix());
    }
    n = static_cast<int>(z.size());
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(np);
    for (const auto& v : z) mean += v / n;
    double sum = 0;
    for (const auto& v : z) sum += (v - mean).squaredNorm();
    return sum / (n - 1);
  };
  for (std::size_t k = 1; k < t.size(); ++k) {
    const long interval = t[k][0] == "All" ? -1 : std::stol(t[k][0]);
    for (int s = 0; s < 3; ++s) {
      int n = 0;
      const double expected = trace(interval, s, n);
      double shown = 0;
      int shown_n = 0;
      ASSERT_EQ(std::sscanf(t[k][1 + s].c_str(), "%lf (%d)", &shown, &shown_n), 2) << t[k][1 + s];
      EXPECT_NEAR(shown, expected, 1e-3 * expected) << t[k][0] << " stage " << s;
      EXPECT_EQ(shown_n, n);
    }
  }
  // The synthetic clouds contract OLS -> SDP -> CLIE (noise 0.01, <=0.005, 0.001).
  int n = 0;
  EXPECT_LT(trace(-1, 2, n), trace(-1, 0, n));
}

TEST_F(Report, AppendixIsSortedAndShowsTheFailedClie) {
  std::vector<std::pair<std::string, long>> shown, expected;
  for (const char* fam : {"AG", "AP", "PA", "PB", "PC"}) {
    const auto t = md_table(*md_, std::string("### ") + fam + "\n");
    ASSERT_EQ(t.size(), 5u) << fam;
    for (std::size_t k = 1; k < t.size(); ++k) shown.emplace_back(t[k][0], std::stol(t[k][1]));
    if (std::string(fam) == "PB") {
      const int clie = column(t, "CLIE");
      EXPECT_EQ(t[2][1], "20");
      EXPECT_EQ(t[2][clie], "failed: NO_CONVERGENCE: simulation diverged at t = 3.2 s");
    }
  }
  for (const auto& r : study().runs) expected.emplace_back(r.trajectory, ms(r.interval));
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(shown, expected);
  EXPECT_NE(md_->find("CLIE failed for PB03@20ms"), std::string::npos);
}

TEST_F(Report, FinalParameterTableHasTruthAndRelativeError) {
  const auto t = md_table(*md_, "## Final parameters");
  ASSERT_EQ(t.size(), 1u + np);
  const int accepted = column(t, "Accepted"), truth = column(t, "Truth"), rel = column(t, "Rel. error");
  for (int i = 0; i < np; ++i) {
    EXPECT_EQ(t[i + 1][0], study().names[i]);
    EXPECT_NEAR(std::stod(t[i + 1][accepted]), study().phi_rescue(i), 1e-5 * std::abs(study().phi_rescue(i)));
    EXPECT_NEAR(std::stod(t[i + 1][truth]), study().truth(i), 1e-5 * std::abs(study().truth(i)));
    const double e = 100 * std::abs((study().phi_rescue(i) - study().truth(i)) / study().truth(i));
    EXPECT_NEAR(std::stod(t[i + 1][rel]), e, 0.006) << study().names[i];
  }
}

TEST_F(Report, ParametersYamlReadsBackBitForBit) {
  const YAML::Node y = YAML::LoadFile((*dir_ / "parameters.yaml").string());
  EXPECT_EQ(y["robot"].as<std::string>(), "crane_x7");
  EXPECT_EQ(y["model"].as<std::string>(), "reduced");
  EXPECT_EQ(y["source_run"].as<std::string>(), "AG02@40ms");
  EXPECT_TRUE(y["rescued"].as<bool>());
  EXPECT_TRUE(y["accepted"].as<bool>());
  EXPECT_EQ(bits(y["final_lambda_min"].as<double>()), bits(study().final_lambda_min));
  EXPECT_EQ(y["rescue_eps"].as<double>(), 0);
  const YAML::Node p = y["parameters"];
  ASSERT_EQ(p.size(), static_cast<std::size_t>(np));
  for (int i = 0; i < np; ++i) {
    EXPECT_EQ(p[i]["name"].as<std::string>(), study().names[i]);
    EXPECT_EQ(p[i]["unit"].as<std::string>(), study().units[i]);
    EXPECT_EQ(bits(p[i]["value"].as<double>()), bits(study().phi_rescue(i))) << study().names[i];
  }
}

TEST_F(Report, ParametersCsvRowsParseBack) {
  std::istringstream in(read_text(*dir_ / "parameters.csv"));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "name,unit,value,ols,sdp,clie");
  const RunRecord& r = study().runs[synthetic_->selected];
  int i = 0;
  while (std::getline(in, line)) {
    ASSERT_LT(i, np);
    std::vector<std::string> f;
    std::stringstream cells(line);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    ASSERT_EQ(f.size(), 6u) << line;
    EXPECT_EQ(f[0], study().names[i]);
    EXPECT_EQ(f[1], study().units[i]);
    EXPECT_EQ(bits(std::strtod(f[2].c_str(), nullptr)), bits(study().phi_rescue(i)));
    EXPECT_EQ(bits(std::strtod(f[3].c_str(), nullptr)), bits(r.phi_ols(i)));
    EXPECT_EQ(bits(std::strtod(f[4].c_str(), nullptr)), bits(r.phi_sdp(i)));
    EXPECT_EQ(bits(std::strtod(f[5].c_str(), nullptr)), bits(r.phi_clie(i)));
    ++i;
  }
  EXPECT_EQ(i, np);
}

TEST_F(Report, PcaFigureHasOneMarkerPerScoreAndCoveringTicks) {
  const std::string svg = read_text(*dir_ / "figures" / "pca_clouds.svg");
  EXPECT_TRUE(balanced(svg));
  const auto& pca = study().pca;
  const Eigen::MatrixXd* stages[] = {&pca.ols, &pca.sdp, &pca.clie};
  const auto ps = panels(svg);
  ASSERT_EQ(ps.size(), 3u);
  std::size_t total = 0;
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (int s = 0; s < 3; ++s) {
    std::size_t finite = 0;
    for (int i = 0; i < stages[s]->rows(); ++i)
      if (stages[s]->row(i).allFinite()) {
        ++finite;
        for (int c = 0; c < 2; ++c) lo[c] = std::min(lo[c], (*stages[s])(i, c)), hi[c] = std::max(hi[c], (*stages[s])(i, c));
      }
    EXPECT_EQ(count(ps[s], "class=\"marker\""), finite) << s;
    total += finite;
    // The representative ringed and labelled, AP01 labelled at every interval.
    EXPECT_EQ(count(ps[s], "class=\"ring\""), 1u);
    EXPECT_EQ(count(ps[s], ">AG02@40ms</text>"), 1u);
    for (const char* id : {"AP01@10ms", "AP01@20ms", "AP01@40ms", "AP01@80ms"})
      EXPECT_EQ(count(ps[s], std::string(">") + id + "</text>"), 1u) << id;
  }
  EXPECT_EQ(total, 3 * study().runs.size() - 1);  // the failed run has no CLIE score
  EXPECT_EQ(count(svg, "class=\"marker\""), total);
  // Shared axes: every panel's ticks cover all three stages' scores.
  for (const auto& p : ps) {
    const auto xt = tick_values(p, "xtick"), yt = tick_values(p, "ytick");
    ASSERT_GE(xt.size(), 2u);
    ASSERT_GE(yt.size(), 2u);
    EXPECT_LE(xt.front(), lo[0]);
    EXPECT_GE(xt.back(), hi[0]);
    EXPECT_LE(*std::min_element(yt.begin(), yt.end()), lo[1]);
    EXPECT_GE(*std::max_element(yt.begin(), yt.end()), hi[1]);
    EXPECT_EQ(tick_values(p, "xtick"), tick_values(ps[0], "xtick"));
  }
  for (const char* legend : {">10 ms<", ">20 ms<", ">40 ms<", ">80 ms<"}) EXPECT_EQ(count(svg, legend), 1u) << legend;
  EXPECT_EQ(count(svg, "class=\"legend-marker\""), 4u);
}

TEST_F(Report, ValidationFigureStacksTheChosenJoints) {
  const std::string svg = read_text(*dir_ / "figures" / "validation_V03.svg");
  EXPECT_TRUE(balanced(svg));
  const auto ps = panels(svg);
  ASSERT_EQ(ps.size(), 3u);
  const ValidationRecord& v = study().validation[2];
  const int joints[] = {1, 3, 5};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NE(ps[k].find(">J" + std::to_string(joints[k] + 1) + "</text>"), std::string::npos);
    EXPECT_EQ(count(ps[k], "<polyline"), 3u);  // measured, CLIE, rescue
    EXPECT_EQ(count(ps[k], "<polyline class=\"line\" fill=\"none\" stroke=\"#000000\""), 1u);
    const double lo = std::min({v.tau_measured.col(joints[k]).minCoeff(), v.tau_clie.col(joints[k]).minCoeff(),
                                v.tau_rescue.col(joints[k]).minCoeff()});
    const double hi = std::max({v.tau_measured.col(joints[k]).maxCoeff(), v.tau_clie.col(joints[k]).maxCoeff(),
                                v.tau_rescue.col(joints[k]).maxCoeff()});
    const auto yt = tick_values(ps[k], "ytick"), xt = tick_values(ps[k], "xtick");
    EXPECT_LE(*std::min_element(yt.begin(), yt.end()), lo);
    EXPECT_GE(*std::max_element(yt.begin(), yt.end()), hi);
    EXPECT_LE(xt.front(), 0);
    EXPECT_GE(xt.back(), v.time(v.time.size() - 1));
    // Every sample is a vertex of the measured line.
    const auto start = ps[k].find("points=\"", ps[k].find("stroke=\"#000000\""));
    const std::string points = ps[k].substr(start + 8, ps[k].find('"', start + 8) - start - 8);
    EXPECT_EQ(count(points, ",") , static_cast<std::size_t>(v.time.size()));
  }
}

TEST_F(Report, RoutingFigureHasOneBarPerRouteAndInterval) {
  const std::string svg = read_text(*dir_ / "figures" / "routing.svg");
  EXPECT_TRUE(balanced(svg));
  EXPECT_EQ(count(svg, "class=\"bar\""), 2 * kIntervals.size());
  for (const char* c : {">10 ms<", ">20 ms<", ">40 ms<", ">80 ms<"}) EXPECT_EQ(count(svg, c), 1u) << c;
}

// --- Missing data -----------------------------------------------------------------------------

TEST(ReportMissingData, BareStudyRendersWithNotes) {
  Synthetic s = make_study();
  StudyResult& st = s.study;
  st.validation.clear();
  st.truth.resize(0);
  st.pca = PcaClouds{};
  st.selection = Selection{};
  st.phi_rescue.resize(0);
  st.rescued = false;
  st.accepted = false;
  const fs::path dir = fresh_dir("bare");
  std::vector<fs::path> written;
  ASSERT_NO_THROW(written = write_report(st, dir));
  const std::vector<fs::path> expected{dir / "figures" / "routing.svg", dir / "report.md", dir / "parameters.yaml",
                                       dir / "parameters.csv"};
  EXPECT_EQ(written, expected);
  const std::string md = read_text(dir / "report.md");
  for (const char* note : {"No representative was selected", "No validation records",
                           "No PCA scores for the runs", "**Accepted model**: none",
                           "No CLIE and rescued parameter vectors to compare"})
    EXPECT_NE(md.find(note), std::string::npos) << note;
  EXPECT_EQ(md.find("pca_clouds.svg"), std::string::npos);
  EXPECT_EQ(md.find("Truth"), std::string::npos);
  const YAML::Node y = YAML::LoadFile((dir / "parameters.yaml").string());
  EXPECT_TRUE(y["source_run"].IsNull());
  EXPECT_FALSE(y["accepted"].as<bool>());
  EXPECT_EQ(y["parameters"].size(), 0u);
  EXPECT_EQ(read_text(dir / "parameters.csv"), "name,unit,value\n");
  // The dispersion falls back to the pooled standardization and still contracts.
  const auto t = md_table(md, "### Cloud dispersion");
  ASSERT_EQ(t.size(), 6u);
  double ols = 0, clie = 0;
  std::sscanf(t[5][1].c_str(), "%lf", &ols);
  std::sscanf(t[5][3].c_str(), "%lf", &clie);
  EXPECT_LT(clie, ols);
  fs::remove_all(dir);
}

TEST(ReportMissingData, RepresentativeWithFailedClieAndNoRescue) {
  Synthetic s = make_study();
  StudyResult& st = s.study;
  st.selection.run = s.failed;
  st.rescued = false;
  st.accepted = false;
  st.phi_rescue = st.runs[s.selected].phi_clie;  // any vector of the right size
  st.validation.pop_back();                      // no V03: no torque figure
  const fs::path dir = fresh_dir("failed");
  ASSERT_NO_THROW(write_report(st, dir));
  const std::string md = read_text(dir / "report.md");
  const auto t = md_table(md, "## Table V");
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[3][5], "CLIE failed: NO_CONVERGENCE: simulation diverged at t = 3.2 s");
  EXPECT_EQ(t[4][5], "Not rescued; the final audit failed");
  EXPECT_NE(md.find("No torque series for V03"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "figures" / "validation_V03.svg"));
  // The failed run's CLIE column in the parameter table and CSV is empty, not garbage.
  const auto p = md_table(md, "## Final parameters");
  EXPECT_EQ(p[1][column(p, "CLIE")], "--");
  std::istringstream csv(read_text(dir / "parameters.csv"));
  std::string line;
  std::getline(csv, line);
  std::getline(csv, line);
  EXPECT_EQ(line.back(), ',');
  fs::remove_all(dir);
}

TEST(ReportMissingData, MismatchedParameterVectorIsRejected) {
  Synthetic s = make_study();
  s.study.phi_rescue.conservativeResize(np - 1);
  const fs::path dir = fresh_dir("mismatch");
  fs::create_directories(dir);
  EXPECT_THROW(write_parameters_yaml(s.study, dir / "p.yaml"), std::invalid_argument);
  EXPECT_THROW(write_parameters_csv(s.study, dir / "p.csv"), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "p.yaml"));
  // The whole report refuses before writing anything.
  EXPECT_THROW(write_report(s.study, dir / "report"), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "report" / "report.md"));
  fs::remove_all(dir);
}

}  // namespace

namespace {

// A robot without a controller description: CLIE skipped, validation open loop by design.
// The reproduction table must say "n/a", not that the paper's findings failed.
TEST(Reproduction, WithoutAControllerTheClosedLoopFindingsAreNotApplicable) {
  using namespace symoro::identify;
  StudyResult s;
  for (int i = 0; i < 3; ++i) {
    RunRecord r;
    r.trajectory = "arm" + std::to_string(i);
    r.interval = 0.01;
    r.clie_ran = false;
    r.phi_ols = r.phi_sdp = r.phi_clie = Eigen::VectorXd::Constant(2, 1.0 + i);
    s.runs.push_back(r);
  }
  ValidationRecord v;
  v.trajectory = "arm_heldout";
  v.kind = "open-loop";
  v.note = "open loop: no controller description";
  v.rmse_clie = v.rmse_rescue = 0.06;
  s.validation.push_back(v);
  const std::vector<Finding> f = paper_findings(s);
  ASSERT_GE(f.size(), 3u);
  EXPECT_EQ(f[0].verdict, "n/a") << f[0].note;  // clouds
  EXPECT_NE(f[0].note.find("CLIE did not run"), std::string::npos);
  EXPECT_EQ(f[2].verdict, "n/a") << f[2].note;  // validation
  EXPECT_EQ(f[2].study, "1 of 1 finite, 0 closed loop");
  // A closed loop that diverged into the open-loop fallback is a failed finding.
  s.validation[0].note = "the closed loop of the final vector diverged at t = 1 s; open-loop values";
  EXPECT_EQ(paper_findings(s)[2].verdict, "not reproduced");
}

}  // namespace
