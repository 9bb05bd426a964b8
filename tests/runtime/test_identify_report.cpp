// The study report: its numbers against independent computations from a synthetic StudyResult
// (routing counts, route examples, rescue deltas, validation means, cloud dispersion, Appendix A
// order), the parameter files read back exactly (yaml-cpp, CSV), graceful output for missing
// data, and the reproduction table without a controller. The figures:
// test_identify_report_figures.cpp.
#include "report_test_support.hpp"
#include "symoro/io/parameters_yaml.hpp"

namespace {

using namespace symoro::study;
using namespace symoro::test::report;
namespace fs = std::filesystem;

// --- The report -----------------------------------------------------------------------------

TEST_F(Report, WritesEveryFileAtomicallyAndReturnsThem) {
  const std::vector<fs::path> expected{*dir_ / "figures" / "routing.svg",
                                       *dir_ / "figures" / "pca_clouds.svg",
                                       *dir_ / "figures" / "validation_V03.svg",
                                       *dir_ / "report.md",
                                       *dir_ / "parameters.yaml",
                                       *dir_ / "parameters.csv"};
  EXPECT_EQ(*written_, expected);
  for (const auto& p : expected) EXPECT_TRUE(fs::is_regular_file(p)) << p;
  // No temporary file left behind.
  for (const auto& dir : {*dir_, *dir_ / "figures"})
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_EQ(e.path().string().find(".symoro-tmp."), std::string::npos) << e.path();
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

// The moves table against the vectors themselves: every stage's move in units of the OLS
// standard deviation, ordered by the rescue's; a well-determined parameter the rescue pushed by
// 10 sigma is flagged and named, one pushed by 2 sigma is not; the relative errors against the
// truth.
TEST(ReportMoves, StagesMovesInOlsStandardDeviations) {
  Synthetic s = make_study();
  StudyResult& st = s.study;
  const RunRecord& r = st.runs[s.selected];
  const Eigen::VectorXd& ols = r.phi_ols;
  // MYR2 (-0.238, sigma 0.002: 0.8 %) pushed 10 sigma; ZZR2 (0.09) 2 sigma: only MYR2 is flagged.
  const int myr2 = 4, zzr2 = 2;
  ASSERT_EQ(st.names[myr2], "MYR2");
  ASSERT_EQ(st.names[zzr2], "ZZR2");
  st.phi_rescue = r.phi_clie;
  st.phi_rescue(myr2) += 10 * r.std_ols(myr2);
  st.phi_rescue(zzr2) -= 2 * r.std_ols(zzr2);
  st.rescued = true;
  const fs::path dir = fresh_dir("moves");
  write_report(st, dir);
  const std::string md = read_text(dir / "report.md");
  EXPECT_NE(md.find("moved 1 well-determined parameter by more than 3 σ (largest: MYR2, +10.0 σ)"), std::string::npos);
  const double e_ols = (ols - st.truth).norm() / st.truth.norm(),
               e_acc = (st.phi_rescue - st.truth).norm() / st.truth.norm();
  char text[64];
  std::snprintf(text, sizeof text, "OLS %.2f %%", 100 * e_ols);
  EXPECT_NE(md.find(text), std::string::npos) << text;
  std::snprintf(text, sizeof text, "accepted %.2f %%", 100 * e_acc);
  EXPECT_NE(md.find(text), std::string::npos) << text;
  const auto t = md_table(md, "## Parameter moves");
  ASSERT_GE(t.size(), 3u);
  EXPECT_EQ(t[1][0], "MYR2");
  EXPECT_EQ(t[1][9], "yes");
  EXPECT_EQ(t[2][0], "ZZR2");
  EXPECT_EQ(t[2][9], "");
  for (std::size_t k = 1; k < t.size(); ++k) {
    const int i = static_cast<int>(std::find(st.names.begin(), st.names.end(), t[k][0]) - st.names.begin());
    ASSERT_LT(i, static_cast<int>(st.names.size()));
    const double sd = r.std_ols(i);
    EXPECT_NEAR(std::stod(t[k][5]), (r.phi_sdp(i) - ols(i)) / sd, 0.006) << t[k][0];
    EXPECT_NEAR(std::stod(t[k][6]), (r.phi_clie(i) - ols(i)) / sd, 0.006) << t[k][0];
    EXPECT_NEAR(std::stod(t[k][7]), (st.phi_rescue(i) - r.phi_clie(i)) / sd, 0.006) << t[k][0];
    EXPECT_NEAR(std::stod(t[k][8]), (st.phi_rescue(i) - ols(i)) / sd, 0.006) << t[k][0];
  }
  fs::remove_all(dir);
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

// The study's torque timing, which fits on top of the parameters default to (dynid payload,
// predict): 0 for this study, and a shifted one's as it was given.
TEST_F(Report, ParametersYamlCarriesTheStudysTorqueDelay) {
  EXPECT_EQ(symoro::io::parameters_torque_delay((*dir_ / "parameters.yaml").string()), 0.0);
  StudyResult shifted = study();
  shifted.torque_delay = -0.0023;
  const fs::path file = *dir_ / "shifted.parameters.yaml";
  write_parameters_yaml(shifted, file);
  EXPECT_DOUBLE_EQ(symoro::io::parameters_torque_delay(file.string()).value_or(0), -0.0023);
  fs::remove(file);
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
  for (const char* note : {"No representative was selected", "No validation records", "No PCA scores for the runs",
                           "**Accepted model**: none", "No CLIE and rescued parameter vectors to compare"})
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
  using namespace symoro::study;
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
