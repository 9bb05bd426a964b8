// Importing controller exports: synthetic files written here from known motions (degrees,
// milliseconds, irregular stamps, stale rows, a duplicate stamp), imported, read back with
// io::read_log and compared bit for bit with the known values converted by the documented
// formulas (t / 1000, deg * (pi / 180), tau * scale); the differentiated velocity against the
// exact derivative of a quadratic; every rejected input by its line.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "symoro/error.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"

namespace fs = std::filesystem;
namespace io = symoro::io;
using symoro::DataError;

namespace {

constexpr double kPi = 3.14159265358979323846;

void write_text(const fs::path& p, const std::string& content) {
  std::ofstream out(p, std::ios::binary);
  out << content;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string num(double v) { return io::number_text(v); }

class Import : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("symoro_import_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

// ---- The 6-joint export: degrees, milliseconds, mN m, a header, comments, a text column ------

io::ImportTarget six_joints() { return {"arm6", {"j1", "j2", "j3", "j4", "j5", "j6"}, {}}; }

io::ImportMapping six_mapping() {
  io::ImportMapping m;
  m.time = "time_ms";
  m.q = "pos_*";
  m.qd = "vel_%";  // this exporter numbers velocities from 0
  m.tau = "eff_*";
  m.time_unit = io::TimeUnit::ms;
  m.angle_unit = io::AngleUnit::deg;
  m.torque_scale = 0.001;  // mN m
  return m;
}

// What the exporter wrote (the parsed values of its text), and where.
struct Export6 {
  std::vector<double> t_ms;                        // per written log row
  std::vector<std::vector<double>> pos, vel, eff;  // [row][joint], as written (deg, deg/s, mN m)
  std::vector<int> stale_lines, duplicate_lines;
};

// Joint j: A sin(w t + p) deg with A = 20 + 5 j, w = 2 pi (0.3 + 0.1 j), p = 0.4 j.
// Stamps: k ms, every 4th one off by -30..30 us; every 20th row (5 %) repeats the previous row's
// data with its own stamp; row 1000 is written twice (same stamp, same values).
Export6 write_six(const fs::path& file, int rows) {
  Export6 e;
  std::string text = "# exported by the arm's controller\n# 2 comment lines, then the header\n";
  text += "time_ms";
  for (const char* g : {"pos_", "eff_"})
    for (int j = 1; j <= 6; ++j) text += "," + std::string(g) + std::to_string(j);
  for (int j = 0; j < 6; ++j) text += ",vel_" + std::to_string(j);
  text += ",mode\n";
  int line = 3;
  for (int k = 0; k < rows; ++k) {
    const double t_ms = k + (k % 4 == 2 ? ((k * 37) % 7 - 3) * 0.01 : 0.0);
    std::vector<double> pos(6), vel(6), eff(6);
    const bool stale = k % 20 == 19;
    for (int j = 0; j < 6; ++j) {
      const double t = t_ms / 1000, a = 20 + 5 * j, w = 2 * kPi * (0.3 + 0.1 * j), p = 0.4 * j;
      pos[j] = stale ? e.pos.back()[j] : a * std::sin(w * t + p);
      vel[j] = stale ? e.vel.back()[j] : a * w * std::cos(w * t + p);
      eff[j] = stale ? e.eff.back()[j] : 1500 * std::sin(w * t) + 100 * j;
    }
    std::string row = num(t_ms);
    for (double v : pos) row += "," + num(v);
    for (double v : eff) row += "," + num(v);
    for (double v : vel) row += "," + num(v);
    row += k % 2 ? ",run\n" : ",RUN\n";  // an unmapped text column is never parsed
    text += row;
    ++line;
    if (stale) e.stale_lines.push_back(line);
    e.t_ms.push_back(t_ms);
    e.pos.push_back(pos);
    e.vel.push_back(vel);
    e.eff.push_back(eff);
    if (k == 1000) {
      text += row;
      e.duplicate_lines.push_back(++line);
    }
  }
  write_text(file, text);
  return e;
}

// ---- The 2-joint export: seconds, whitespace, no header, no velocity -------------------------

// q1 = 0.3 + 0.5 t - 0.2 t^2, q2 = -1 + 2 t + 0.7 t^2 (rad), at 1 kHz with irregular stamps
// (0.6 to 1.4 ms apart), every 20th row stale, row 300 written twice.
struct Export2 {
  std::vector<double> t;
  std::vector<int> stale_rows;  // log rows that are stale
  std::vector<int> stale_lines, duplicate_lines;
};

double q2_exact(int j, double t, int derivative) {
  const double c0 = j == 0 ? 0.3 : -1, c1 = j == 0 ? 0.5 : 2, c2 = j == 0 ? -0.2 : 0.7;
  return derivative == 0 ? c0 + c1 * t + c2 * t * t : c1 + 2 * c2 * t;
}

Export2 write_two(const fs::path& file, int rows, double t0 = 100.0) {
  Export2 e;
  std::string text = "# t q1 q2 tau1 tau2\n";
  int line = 1;
  double t = t0, previous_q[2] = {0, 0};
  for (int k = 0; k < rows; ++k) {
    if (k > 0) t += 0.001 + ((k * 13) % 9 - 4) * 1e-4;
    const bool stale = k % 20 == 19;
    double q[2];
    for (int j = 0; j < 2; ++j) q[j] = stale ? previous_q[j] : q2_exact(j, t - t0, 0);
    // Constant torques: whether a row is stale is decided by q.
    const std::string row = num(t) + "  " + num(q[0]) + "\t" + num(q[1]) + "   0 1.5\n";
    text += row;
    ++line;
    if (stale) {
      e.stale_lines.push_back(line);
      e.stale_rows.push_back(static_cast<int>(e.t.size()));
    }
    e.t.push_back(t);
    previous_q[0] = q[0];
    previous_q[1] = q[1];
    if (k == 300) {
      text += "# a comment between rows\n" + row;
      line += 2;
      e.duplicate_lines.push_back(line);
    }
  }
  write_text(file, text);
  return e;
}

io::ImportMapping two_mapping() {
  io::ImportMapping m;
  m.time = "1";
  m.q = "2-3";
  m.tau = "4,5";
  return m;
}

io::ImportTarget two_joints() { return {"arm2", {"shoulder", "elbow"}, {}}; }

// Each rejected input: file, line and a piece of the message.
void expect_error(const std::function<void()>& f, const std::string& file, int line, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected " << part;
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), file) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

}  // namespace

TEST_F(Import, SixJointsInDegreesAndMillisecondsReadBackExactly) {
  const fs::path input = dir_ / "arm_run.csv";
  const int rows = 3000;
  const Export6 e = write_six(input, rows);
  io::DatasetImport di;
  di.target = six_joints();
  di.mapping = six_mapping();
  di.inputs = {{input, "", false}};
  const io::DatasetImportResult r = io::import_dataset(dir_ / "data", di);
  ASSERT_EQ(r.logs.size(), 1u);
  const io::ImportedLog& imported = r.logs[0];
  EXPECT_EQ(imported.rows, rows + 1);
  EXPECT_EQ(imported.stale_lines, e.stale_lines);
  EXPECT_EQ(imported.stale_lines.size(), 150u);                 // 5 % of 3000
  EXPECT_EQ(imported.duplicate_lines, std::vector<int>{1005});  // row 1000 is on line 1004
  EXPECT_EQ(imported.columns.at("q1"), "'pos_1' (column 2)");
  EXPECT_EQ(imported.columns.at("qd1"), "'vel_0' (column 14)");

  const io::Log log = io::read_log(dir_ / "data" / "arm_run.csv");
  ASSERT_EQ(log.samples(), rows);
  ASSERT_EQ(log.joints(), 6);
  EXPECT_EQ(log.meta.robot, "arm6");
  EXPECT_EQ(log.meta.trajectory, "arm_run");
  EXPECT_EQ(log.meta.source, "robot");
  EXPECT_EQ(log.meta.joints, six_joints().joints);
  EXPECT_EQ(log.meta.velocity, io::Velocity::measured);
  // Half the intervals are 1 ms (to rounding), the others 1 ms -+ the jitter of every 4th
  // stamp: the median is 1 ms to the microsecond.
  EXPECT_EQ(log.meta.sample_time, 0.001);
  EXPECT_FALSE(log.has_references());
  for (int k = 0; k < rows; ++k) {
    ASSERT_EQ(log.time[k], e.t_ms[k] / 1000) << k;  // kept as logged
    for (int j = 0; j < 6; ++j) {
      ASSERT_EQ(log.q(k, j), e.pos[k][j] * (kPi / 180)) << k << " " << j;
      ASSERT_EQ(log.qd(k, j), e.vel[k][j] * (kPi / 180)) << k << " " << j;
      ASSERT_EQ(log.tau(k, j), e.eff[k][j] * 0.001) << k << " " << j;
    }
  }
  // Against the motion itself: the exporter's text is the shortest round trip, so the log is
  // the sinusoid to rounding (stale rows hold the previous row's values by design).
  const int k = 1234;
  EXPECT_NEAR(log.q(k, 2), 30 * kPi / 180 * std::sin(2 * kPi * 0.5 * log.time[k] + 0.8), 1e-14);
  EXPECT_NEAR(log.qd(k, 2), 30 * kPi / 180 * 2 * kPi * 0.5 * std::cos(2 * kPi * 0.5 * log.time[k] + 0.8), 1e-13);

  // The dataset manifest and the record of the import.
  const symoro::io::Dataset d = symoro::io::read_dataset(dir_ / "data");
  EXPECT_EQ(d.robot, "arm6");
  EXPECT_EQ(d.source, "imported");
  ASSERT_EQ(d.runs.size(), 1u);
  EXPECT_EQ(d.runs[0].trajectory, "arm_run");
  EXPECT_EQ(d.runs[0].family, "F");
  EXPECT_TRUE(std::isinf(d.runs[0].window_start) && std::isinf(d.runs[0].window_end));
  const std::string manifest = read_text(dir_ / "data" / "dataset.yaml");
  EXPECT_NE(manifest.find("import: {inputs: 1, rows: 3001, written: 3000, stale_rows: 150, duplicate_rows: 1}"),
            std::string::npos)
      << manifest;
  const io::ImportMapping again = io::read_import_mapping(dir_ / "data" / "import.yaml");
  EXPECT_EQ(again.time, "time_ms");
  EXPECT_EQ(again.q, "pos_*");
  EXPECT_EQ(again.qd, "vel_%");
  EXPECT_EQ(again.tau, "eff_*");
  EXPECT_EQ(again.time_unit, io::TimeUnit::ms);
  EXPECT_EQ(again.angle_unit, io::AngleUnit::deg);
  EXPECT_EQ(again.torque_scale, 0.001);
  EXPECT_NE(read_text(dir_ / "data" / "import.yaml").find("duplicate_lines: [1005]"), std::string::npos);

  // The same import again: nothing is replaced.
  const std::string before = read_text(dir_ / "data" / "arm_run.csv");
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, (dir_ / "data" / "dataset.yaml").string(), 0,
               "never replaces a file");
  EXPECT_EQ(read_text(dir_ / "data" / "arm_run.csv"), before);
}

// Without qd the velocity is the derivative of the parabola through each row and its fresh
// neighbours: exact for a quadratic whatever the spacing, so it matches c1 + 2 c2 t to
// rounding (the stamps are ~100 s, so t carries ~1.4e-14 s of rounding, times 1/h: 1e-9).
TEST_F(Import, TwoJointsWhitespaceWithoutHeaderDifferentiatesVelocity) {
  const fs::path input = dir_ / "two.txt";
  const int rows = 2000;
  const Export2 e = write_two(input, rows);
  const io::ImportedLog imported = io::import_log(input, two_mapping(), two_joints());
  EXPECT_EQ(imported.rows, rows + 1);
  EXPECT_EQ(imported.stale_lines, e.stale_lines);
  EXPECT_EQ(imported.duplicate_lines, e.duplicate_lines);
  EXPECT_EQ(imported.duplicate_lines, std::vector<int>{304});
  const io::Log& log = imported.log;
  ASSERT_EQ(log.samples(), rows);
  EXPECT_EQ(log.meta.velocity, io::Velocity::differentiated);
  std::vector<bool> stale(rows, false);
  for (int k : e.stale_rows) stale[k] = true;
  double worst = 0;
  for (int k = 0; k < rows; ++k) {
    ASSERT_EQ(log.time[k], e.t[k]);
    ASSERT_EQ(log.tau(k, 1), 1.5);
    for (int j = 0; j < 2; ++j) {
      if (stale[k]) {
        // A stale row repeats the previous state, velocity included.
        ASSERT_EQ(log.qd(k, j), log.qd(k - 1, j)) << k;
        ASSERT_EQ(log.q(k, j), log.q(k - 1, j)) << k;
      } else {
        ASSERT_EQ(log.q(k, j), q2_exact(j, e.t[k] - 100.0, 0));
        worst = std::max(worst, std::abs(log.qd(k, j) - q2_exact(j, e.t[k] - 100.0, 1)));
      }
    }
  }
  EXPECT_LT(worst, 1e-9);

  // Through a log file: the sidecar says the velocity was differentiated.
  const fs::path csv = dir_ / "out.csv";
  io::write_log(csv, log);
  EXPECT_NE(read_text(io::metadata_path(csv)).find("velocity: differentiated"), std::string::npos);
  EXPECT_EQ(io::read_log_metadata(csv).velocity, io::Velocity::differentiated);
}

// By hand: t = 0, 1, 3 with q = t^2 (a parabola through the three points is q itself):
// qd = 0, 2, 6; a stale row at t = 2 (q repeated) is skipped and repeats qd = 2.
TEST(ImportDifferentiation, ParabolaThroughIrregularPointsByHand) {
  Eigen::VectorXd t(4);
  t << 0, 1, 2, 3;
  Eigen::MatrixXd q(4, 1);
  q << 0, 1, 1, 9;
  const Eigen::MatrixXd qd = io::differentiate_positions(t, q, {false, false, true, false});
  EXPECT_DOUBLE_EQ(qd(0, 0), 0);
  EXPECT_DOUBLE_EQ(qd(1, 0), 2);
  EXPECT_EQ(qd(2, 0), qd(1, 0));
  EXPECT_DOUBLE_EQ(qd(3, 0), 6);
}

TEST(ImportSampleTime, MedianRoundedToTheMicrosecond) {
  Eigen::VectorXd t(6);
  t << 0, 0.0019996, 0.0040003, 0.0060001, 0.0080007, 0.0100004;  // 1.9996 .. 2.0006 ms apart
  EXPECT_EQ(io::median_sample_time(t, "x"), 0.002);
  Eigen::VectorXd one(1);
  one << 1;
  EXPECT_THROW(io::median_sample_time(one, "x"), DataError);
}

// --split 0.7: each run by time into its first 70 % (family F) and the rest (V), recorded in
// dataset.yaml; read_run_log gives each window's rows, and they partition the log.
TEST_F(Import, SplitRecordsWindowsThatPartitionEachRun) {
  write_six(dir_ / "a.csv", 1500);
  write_six(dir_ / "b.csv", 800);
  io::DatasetImport di;
  di.target = six_joints();
  di.mapping = six_mapping();
  di.inputs = {{dir_ / "a.csv", "", false}, {dir_ / "b.csv", "second", false}};
  di.split = 0.7;
  io::import_dataset(dir_ / "data", di);
  const symoro::io::Dataset d = symoro::io::read_dataset(dir_ / "data");
  ASSERT_EQ(d.runs.size(), 4u);
  const std::vector<std::pair<std::string, std::string>> expected{
      {"a", "F"}, {"a_heldout", "V"}, {"second", "F"}, {"second_heldout", "V"}};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(d.runs[i].trajectory, expected[i].first);
    EXPECT_EQ(d.runs[i].family, expected[i].second);
  }
  for (int pair = 0; pair < 2; ++pair) {
    const auto& fit = d.runs[2 * pair];
    const auto& held = d.runs[2 * pair + 1];
    EXPECT_EQ(fit.file, held.file);
    const io::Log whole = io::read_log(fit.file);
    const double t0 = whole.time[0], t1 = whole.time[whole.samples() - 1];
    const double cut = t0 + 0.7 * (t1 - t0);
    EXPECT_EQ(fit.window_start, t0);
    EXPECT_EQ(fit.window_end, cut);
    EXPECT_EQ(held.window_start, cut);
    EXPECT_TRUE(std::isinf(held.window_end));
    const io::Log a = symoro::io::read_run_log(fit), b = symoro::io::read_run_log(held);
    EXPECT_EQ(a.meta.trajectory, fit.trajectory);
    EXPECT_EQ(b.meta.trajectory, held.trajectory);
    ASSERT_EQ(a.samples() + b.samples(), whole.samples());
    EXPECT_LT(a.time[a.samples() - 1], cut);
    EXPECT_GE(b.time[0], cut);
    // Stamps kept as logged, rows unchanged.
    EXPECT_EQ(a.time[0], whole.time[0]);
    EXPECT_EQ(b.time[0], whole.time[a.samples()]);
    EXPECT_EQ(b.q.row(0), whole.q.row(a.samples()));
    EXPECT_EQ(b.tau.row(b.samples() - 1), whole.tau.row(whole.samples() - 1));
  }
  // 1500 rows of ~1 ms: the cut is at 0.7 * 1499 ms, so the fitting part has 1050 rows (0..1049 ms).
  EXPECT_EQ(symoro::io::read_run_log(d.runs[0]).samples(), 1050);
  EXPECT_NE(read_text(dir_ / "data" / "dataset.yaml").find("split: 0.7\n"), std::string::npos);

  // The dataset belongs to arm6; another robot is refused at the line of robot:.
  EXPECT_NO_THROW(symoro::io::check_dataset_robot(d, "arm6"));
  expect_error([&] { symoro::io::check_dataset_robot(d, "crane_x7"); }, (d.dir / "dataset.yaml").string(), 2,
               "made for robot 'arm6', not 'crane_x7'");
}

TEST_F(Import, DatasetWindowsAreChecked) {
  write_six(dir_ / "a.csv", 300);
  io::DatasetImport di;
  di.target = six_joints();
  di.mapping = six_mapping();
  di.inputs = {{dir_ / "a.csv", "", false}};
  io::import_dataset(dir_ / "data", di);
  const fs::path manifest = dir_ / "data" / "dataset.yaml";
  std::string text = read_text(manifest);
  const std::size_t runs = text.find("runs:\n");
  write_text(manifest, text.substr(0, runs) +
                           "runs:\n  - {trajectory: a, family: F, trial: 1, file: a.csv,\n"
                           "     window: [2, 1]}\n");
  const int window_line = static_cast<int>(std::count(text.begin(), text.begin() + runs, '\n')) + 3;
  expect_error([&] { symoro::io::read_dataset(dir_ / "data"); }, manifest.string(), window_line, "not an interval");
  write_text(manifest,
             text.substr(0, runs) + "runs:\n  - {trajectory: a, family: F, trial: 1, file: a.csv, window: [5, 6]}\n");
  const symoro::io::Dataset d = symoro::io::read_dataset(dir_ / "data");
  expect_error([&] { symoro::io::read_run_log(d.runs[0]); }, d.runs[0].file.string(), 0,
               "holds none of the log's samples");
}

// The manifest's one writer against its one reader: every field, awkward names (quotes, a
// colon, a '#', a backslash, a control byte), numbers that need all 17 digits, open windows,
// and files given absolute or relative to the folder.
// A run's file outside the dataset folder was used without a word (issue 42, item 17).
TEST_F(Import, ARunFileOutsideTheDatasetFolderIsRefused) {
  fs::create_directories(dir_ / "data" / "sub");
  write_text(dir_ / "outside.csv", "");
  write_text(dir_ / "data" / "sub" / "in.csv", "");
  const fs::path manifest = dir_ / "data" / "dataset.yaml";
  for (const std::string& file :
       std::vector<std::string>{"../outside.csv", (dir_ / "outside.csv").string(), "sub/../../outside.csv"}) {
    write_text(manifest,
               "format: symoro-dataset 1\nrobot: arm2\nruns:\n  - trajectory: a\n    family: F\n    trial: 1\n"
               "    file: " +
                   file + "\n");
    expect_error([&] { io::read_dataset(dir_ / "data"); }, manifest.string(), 7,
                 "file '" + file + "' is outside the dataset folder: a dataset's logs are in its folder");
  }
  write_text(manifest,
             "format: symoro-dataset 1\nrobot: arm2\nruns:\n  - {trajectory: a, family: F, trial: 1, file: "
             "sub/../sub/in.csv}\n");
  EXPECT_EQ(io::read_dataset(dir_ / "data").runs.at(0).file, dir_ / "data" / "sub" / "in.csv");
}

TEST_F(Import, DatasetManifestReadsBackWhatWasWritten) {
  const fs::path data = dir_ / "data";
  fs::create_directories(data);
  const std::vector<std::string> files = {"a b.csv", "q\"uote: #x.csv", "back\\slash.csv"};
  for (const auto& f : files) write_text(data / f, "");
  write_text(data / "over.yaml", "effects: {}\n");
  symoro::io::Dataset w;
  w.dir = data;
  w.robot = "arm: \"six\"";
  w.source = "imported";
  w.twin = "/robots/arm6/twin.yaml";
  w.twin_overrides = "over.yaml";
  w.twin_record = symoro::io::TwinDatasetRecord{18446744073709551615ull, 3, {"coulomb", "sensor_noise"}};
  w.split = 0.1 + 0.2;  // 0.30000000000000004
  w.import = symoro::io::ImportCounts{2, 1001, 1000, 7, 1};
  w.imported = {{"a b.csv", 600, 4, 1, 0.001, "measured"}, {"q\"uote: #x.csv", 401, 3, 0, 1.0 / 3, "differentiated"}};
  const double cut = 84.21370000000001;
  w.runs = {{"long", "F", 1, "a b.csv", 0.000512, cut},
            {"long_heldout", "V", 1, data / "a b.csv", cut, std::numeric_limits<double>::infinity()},
            {"tab\there", "AG", 2, "q\"uote: #x.csv"},
            {"early", "F", 1, data / "back\\slash.csv", -std::numeric_limits<double>::infinity(), -2.5}};
  symoro::io::write_dataset(w);

  const symoro::io::Dataset r = symoro::io::read_dataset(data);
  EXPECT_EQ(r.robot, w.robot);
  EXPECT_EQ(r.robot_line, 2);
  EXPECT_EQ(r.source, w.source);
  EXPECT_EQ(r.twin, w.twin);
  EXPECT_EQ(r.twin_overrides, (fs::absolute(data) / "over.yaml").string());
  ASSERT_TRUE(r.twin_record.has_value());
  EXPECT_EQ(r.twin_record->seed, w.twin_record->seed);
  EXPECT_EQ(r.twin_record->trials, 3);
  EXPECT_EQ(r.twin_record->effects, w.twin_record->effects);
  EXPECT_EQ(r.split, w.split);
  ASSERT_TRUE(r.import.has_value());
  EXPECT_EQ(r.import->inputs, 2);
  EXPECT_EQ(r.import->rows, 1001);
  EXPECT_EQ(r.import->written, 1000);
  EXPECT_EQ(r.import->stale_rows, 7);
  EXPECT_EQ(r.import->duplicate_rows, 1);
  ASSERT_EQ(r.imported.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(r.imported[i].file, w.imported[i].file);
    EXPECT_EQ(r.imported[i].rows, w.imported[i].rows);
    EXPECT_EQ(r.imported[i].stale_rows, w.imported[i].stale_rows);
    EXPECT_EQ(r.imported[i].duplicate_rows, w.imported[i].duplicate_rows);
    EXPECT_EQ(r.imported[i].sample_time, w.imported[i].sample_time);  // exact: shortest round-trip text
    EXPECT_EQ(r.imported[i].velocity, w.imported[i].velocity);
  }
  ASSERT_EQ(r.runs.size(), w.runs.size());
  const std::vector<std::string> run_files = {files[0], files[0], files[1], files[2]};
  for (std::size_t i = 0; i < w.runs.size(); ++i) {
    EXPECT_EQ(r.runs[i].trajectory, w.runs[i].trajectory);
    EXPECT_EQ(r.runs[i].family, w.runs[i].family);
    EXPECT_EQ(r.runs[i].trial, w.runs[i].trial);
    EXPECT_EQ(r.runs[i].file, fs::absolute(data) / run_files[i]);
    EXPECT_EQ(r.runs[i].window_start, w.runs[i].window_start);
    EXPECT_EQ(r.runs[i].window_end, w.runs[i].window_end);
  }
  // Files inside the folder are listed relative to it, so the folder can move.
  EXPECT_EQ(read_text(data / "dataset.yaml").find(fs::absolute(data).string()), std::string::npos);
  // A record of the wrong type is an error at its line.
  std::string text = read_text(data / "dataset.yaml");
  const std::size_t seed = text.find("seed: ");
  write_text(data / "dataset.yaml", text.substr(0, seed) + "seed: many" + text.substr(text.find('\n', seed)));
  expect_error([&] { symoro::io::read_dataset(data); }, (data / "dataset.yaml").string(),
               static_cast<int>(std::count(text.begin(), text.begin() + seed, '\n')) + 1, "");
}

// ---- Unit plausibility: a unit declared wrong is refused, with its evidence -------------------

// Two revolute joints limited to +-2.8 rad; rows every `step` (in the file's unit), q2 taking
// `peak` on line `peak_line` (1-based; no header).
io::ImportTarget limited_joints() {
  io::ImportTarget t = two_joints();
  t.lower = {-2.8, -2.8};
  t.upper = {2.8, 2.8};
  return t;
}

std::string two_rows(int rows, double step, double peak = 1, int peak_line = 0) {
  std::string text;
  for (int k = 0; k < rows; ++k)
    text += num(k * step) + " " + num(0.01 * k) + " " + num(k + 1 == peak_line ? peak : 0.5) + " 1 2\n";
  return text;
}

io::DatasetImport limited_import(const fs::path& input, const io::ImportMapping& m) {
  io::DatasetImport di;
  di.target = limited_joints();
  di.mapping = m;
  di.inputs = {{input, "", false}};
  return di;
}

// Degrees declared as radians: |q| up to 58.7 rad against limits of +-2.8 (the log).
TEST_F(Import, RefusesAnglesFarBeyondTheJointLimits) {
  const fs::path f = dir_ / "deg.txt";
  write_text(f, two_rows(50, 0.001, 58.7, 17));
  const io::DatasetImport di = limited_import(f, two_mapping());
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, f.string(), 17,
               "joint 2 'elbow' is at 58.7 rad, far outside its limits [-2.8, 2.8] rad (by more than 2.8 rad, "
               "max(0.5 rad, half its range)): are the angles in deg, not rad (--angle deg, units.angle: deg)? "
               "if the values are right, import with --allow-implausible");
  EXPECT_FALSE(fs::exists(dir_ / "data"));
  // Read as degrees, 58.7 is 1.02 rad: within the limits.
  io::ImportMapping deg = two_mapping();
  deg.angle_unit = io::AngleUnit::deg;
  EXPECT_NO_THROW(io::import_dataset(dir_ / "deg", limited_import(f, deg)));
  // The values as written are shown when degrees were declared.
  write_text(f, two_rows(50, 0.001, 3363.3, 9));
  expect_error([&] { io::import_dataset(dir_ / "data", limited_import(f, deg)); }, f.string(), 9,
               "joint 2 'elbow' is at 58.7007 rad (3363.3 as written, read as deg), far outside");
  // Just past the margin is refused, just inside is not: limit 2.8 + margin 2.8.
  write_text(f, two_rows(50, 0.001, 5.61, 3));
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, f.string(), 3, "is at 5.61 rad");
  write_text(f, two_rows(50, 0.001, -5.59, 3));
  EXPECT_NO_THROW(io::import_dataset(dir_ / "near", di));
  // The override imports it as it is.
  write_text(f, two_rows(50, 0.001, 58.7, 17));
  io::DatasetImport allowed = di;
  allowed.allow_implausible = true;
  const io::DatasetImportResult r = io::import_dataset(dir_ / "allowed", allowed);
  EXPECT_EQ(r.logs[0].log.q(16, 1), 58.7);
}

// A prismatic joint in mm read as m; a joint without finite limits is not judged.
TEST_F(Import, PrismaticAndUnlimitedJoints) {
  const fs::path f = dir_ / "mm.txt";
  write_text(f, two_rows(50, 0.001, 450, 5));
  io::DatasetImport di = limited_import(f, two_mapping());
  di.target.prismatic = {false, true};
  di.target.lower[1] = 0.2;
  di.target.upper[1] = 0.9;
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, f.string(), 5,
               "joint 2 'elbow' is at 450 m, far outside its limits [0.2, 0.9] m (by more than 0.35 m");
  di.target.upper[1] = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(io::import_dataset(dir_ / "data", di));
}

// Time stamps in a unit other than the one declared: a median step of 1000.58 "ms", or 0.001 "ms".
TEST_F(Import, RefusesAnImplausibleSampleTime) {
  const fs::path f = dir_ / "slow.txt";
  io::ImportMapping ms = two_mapping();
  ms.time_unit = io::TimeUnit::ms;
  write_text(f, two_rows(50, 1000.58));
  expect_error([&] { io::import_dataset(dir_ / "data", limited_import(f, ms)); }, f.string(), 0,
               "the median time step is 1000.58 ms as written (1.00058 s read as ms), outside the plausible "
               "[0.0001 s, 0.5 s] of a robot's log: is the time unit right (--time-unit, units.time)? "
               "if the values are right, import with --allow-implausible");
  write_text(f, two_rows(50, 0.001));
  expect_error([&] { io::import_dataset(dir_ / "data", limited_import(f, ms)); }, f.string(), 0,
               "the median time step is 0.001 ms as written (1e-06 s read as ms)");
  io::DatasetImport allowed = limited_import(f, ms);
  allowed.allow_implausible = true;
  EXPECT_EQ(io::import_dataset(dir_ / "allowed", allowed).logs[0].log.meta.sample_time, 1e-6);
  io::ImportMapping seconds = two_mapping();
  write_text(f, two_rows(50, 2));
  expect_error([&] { io::import_dataset(dir_ / "data", limited_import(f, seconds)); }, f.string(), 0,
               "the median time step is 2 s as written, outside the plausible [0.0001 s, 0.5 s]");
  // The bounds themselves pass: 0.1 ms and 500 ms.
  write_text(f, two_rows(50, 0.1));
  EXPECT_NO_THROW(io::import_dataset(dir_ / "fast", limited_import(f, ms)));
  write_text(f, two_rows(50, 500));
  EXPECT_NO_THROW(io::import_dataset(dir_ / "slowest", limited_import(f, ms)));
}

// Issue 42, items 15 and 17: radians declared as degrees imported silently; a 24 h gap was
// accepted; stamps of 1e15 ms were read as a 0.977 ms sample time.
TEST_F(Import, FlagsRadiansDeclaredAsDegreesAndGapsAndReadsEpochStampsExactly) {
  const fs::path f = dir_ / "rad.txt";
  write_text(f, two_rows(50, 0.001));  // q1 0 .. 0.49, q2 0.5: radians
  io::ImportMapping deg = two_mapping();
  deg.angle_unit = io::AngleUnit::deg;
  expect_error([&] { io::import_dataset(dir_ / "data", limited_import(f, deg)); }, f.string(), 0,
               "the angles are declared in deg, but every joint stays within +-0.5 and moves at most 0.49 as written: "
               "these look like radians (--angle rad, units.angle: rad)? if the values are right, import with "
               "--allow-implausible");
  io::DatasetImport allowed = limited_import(f, deg);
  allowed.allow_implausible = true;
  EXPECT_NO_THROW(io::import_dataset(dir_ / "allowed", allowed));
  EXPECT_NO_THROW(io::import_dataset(dir_ / "rad", limited_import(f, two_mapping())));

  std::string text;
  for (int k = 0; k < 50; ++k) text += num(k * 0.001 + (k >= 25 ? 86400 : 0)) + " " + num(0.01 * k) + " 0.5 1 2\n";
  write_text(f, text);
  expect_error([&] { io::import_dataset(dir_ / "data", limited_import(f, two_mapping())); }, f.string(), 26,
               "a gap of 86400 s since line 25 (8.64e+07 times the median step 0.001 s): a log is one recording; split "
               "the file there, or if the values are right, import with --allow-implausible");
  allowed = limited_import(f, two_mapping());
  allowed.allow_implausible = true;
  EXPECT_NO_THROW(io::import_dataset(dir_ / "gap", allowed));

  // Milliseconds since an epoch: exact steps, counted from the first stamp, and said.
  text.clear();
  for (int k = 0; k < 50; ++k) text += std::to_string(1000000000000000LL + k) + " " + num(0.01 * k) + " 0.5 1 2\n";
  write_text(f, text);
  io::ImportMapping ms = two_mapping();
  ms.time_unit = io::TimeUnit::ms;
  const io::Log log = io::import_dataset(dir_ / "epoch", limited_import(f, ms)).logs[0].log;
  EXPECT_EQ(log.meta.sample_time, 0.001);
  EXPECT_EQ(log.time[0], 0.0);
  EXPECT_EQ(log.time[49], 0.049);
  EXPECT_NE(log.meta.notes.find("time counted from the first stamp"), std::string::npos) << log.meta.notes;
  // Stamps that double precision holds are kept as written.
  write_text(f, two_rows(50, 1));
  EXPECT_EQ(io::import_dataset(dir_ / "plain", limited_import(f, ms)).logs[0].log.time[49], 0.049);
}

// A split that leaves a part too small to use (--split 1e-9: one sample) is refused.
TEST_F(Import, RefusesASplitLeavingAPartOfTooFewSamples) {
  write_six(dir_ / "a.csv", 300);
  io::DatasetImport di;
  di.target = six_joints();
  di.mapping = six_mapping();
  di.inputs = {{dir_ / "a.csv", "", false}};
  di.split = 1e-9;
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, (dir_ / "a.csv").string(), 0,
               "split 1e-09 at 2.99e-10 s leaves 1 of the 300 samples in the fitting part; each part needs at least 4");
  di.split = 0.999;
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, (dir_ / "a.csv").string(), 0,
               "leaves 1 of the 300 samples in the held-out part; each part needs at least 4");
  EXPECT_FALSE(fs::exists(dir_ / "data"));
  di.split = 0.01;  // at 2.99 ms: rows 0..2 of 1 ms, too few
  expect_error([&] { io::import_dataset(dir_ / "data", di); }, (dir_ / "a.csv").string(), 0,
               "leaves 3 of the 300 samples in the fitting part");
  di.split = 0.011;  // at 3.289 ms: rows 0..3
  EXPECT_NO_THROW(io::import_dataset(dir_ / "data", di));
}

// ---- Rejected inputs, each at its line ---------------------------------------------------------

TEST_F(Import, ErrorsNameTheLine) {
  const fs::path f = dir_ / "bad.txt";
  const auto import = [&](const std::string& text, const io::ImportMapping& m = two_mapping()) {
    write_text(f, text);
    return [m, f] { io::import_log(f, m, two_joints()); };
  };
  const std::string good = "0 0 0 0 0\n0.001 1 1 1 1\n0.002 2 2 2 2\n";
  expect_error(import(good + "0.0015 3 3 3 3\n"), f.string(), 4,
               "time goes backwards: 0.0015 s here, 0.002 s on line 3");
  expect_error(import(good + "0.002 2 2.5 2 2\n"), f.string(), 4,
               "same time stamp as line 3 (0.002 s) but other values: column 3 is 2.5 here, 2 there");
  expect_error(import("# c\n" + good + "0.003 3 nan 3 3\n"), f.string(), 5,
               "column 3 holds 'nan', not a finite number");
  expect_error(import(good + "0.003 3 3 abc 3\n"), f.string(), 4, "'abc' in column 4 is not a number");
  expect_error(import(good + "0.003 3 3 3\n"), f.string(), 4, "row has 4 fields, the first row (line 1) has 5");
  expect_error(import(good + "0.003 3 inf 3 3\n"), f.string(), 4, "not a finite number");

  // The joint count: the robot has 2 joints.
  io::ImportMapping named;
  named.time = "t";
  named.q = "pos_*";
  named.tau = "eff_*";
  const std::string three = "# comment\n\nt,pos_1,pos_2,pos_3,eff_1,eff_2\n0,1,2,3,4,5\n0.001,1,2,3,4,5\n";
  expect_error(import(three, named), f.string(), 3,
               "matches 3 columns numbered 1..3, but the robot 'arm2' has 2 joints");
  // Numbered from 0 with the 1-based pattern: the 0-based one is named.
  const std::string zero = "t,pos_0,pos_1,eff_1,eff_2\n0,1,2,4,5\n0.001,1,2,4,5\n";
  expect_error(import(zero, named), f.string(), 1,
               "matches 2 columns numbered 0..1, but the robot 'arm2' has 2 joints (shoulder, elbow); for numbers from "
               "0 write 'pos_%'");
  const std::string one = "t,pos_1,eff_1,eff_2\n0,1,4,5\n0.001,1,4,5\n";
  expect_error(import(one, named), f.string(), 1, "no column 'pos_2' for joint 2");
  io::ImportMapping positions = two_mapping();
  positions.q = "2-4";
  expect_error(import(good, positions), f.string(), 1, "selects 3 columns but the robot 'arm2' has 2 joints");
  positions.q = "2-3";
  positions.tau = "4-6";
  expect_error(import(good, positions), f.string(), 1, "column 6 does not exist: the file has 5 columns");
  expect_error(import(good, named), f.string(), 1, "selects columns by name, but the file has no header row");
  io::ImportMapping overlap = two_mapping();
  overlap.tau = "3-4";
  expect_error(import(good, overlap), f.string(), 1, "q and tau both select column 3");
  io::ImportMapping partial = two_mapping();
  partial.q_ref = "2-3";
  expect_error(import(good, partial), "command line", 0, "q_ref, qd_ref and qdd_ref come together");
  // CSV with a header: the field count of a row against the header's, text in a named column.
  const std::string csv = "t;pos_1;pos_2;eff_1;eff_2\n0;0;0;0;0\n0.001;x;1;1;1\n";
  expect_error(import(csv, named), f.string(), 3, "'x' in 'pos_1' (column 2) is not a number");
}

// An export cut while it was written (the logger killed, the disk full) ends without a newline,
// its last number perhaps cut to one that still parses ("-0" of "-0.737"): refused at that line.
TEST_F(Import, RefusesALastLineWithoutNewline) {
  const fs::path f = dir_ / "cut.txt";
  const std::string good = "# c\n0 0 0 0 0\n0.001 1 1 1 1\n";
  for (const std::string cut : {"0.002 2 2 2 -0", "0.002 2 2 2 -0.", "0.002 2 2 2 -", "0.002 2 2 2 1e", "0.002 2 2",
                                "0.002 2 2 2 2", "0.002 2 2 2 2\r"}) {
    SCOPED_TRACE(cut);
    write_text(f, good + cut);
    expect_error([&] { io::import_log(f, two_mapping(), two_joints()); }, f.string(), 4,
                 "the last line has no newline at its end: the file may have been cut while it was written");
  }
  write_text(f, good + "# the end");
  expect_error([&] { io::import_log(f, two_mapping(), two_joints()); }, f.string(), 4, "no newline at its end");
  write_text(f, good + "0.002 2 2 2 2\n");
  EXPECT_EQ(io::import_log(f, two_mapping(), two_joints()).rows, 3);
  // Line ends of CR alone were reported as a cut last line (issue 42, item 17).
  write_text(f, "0 0 0 0 0\r0.001 1 1 1 1\r0.002 2 2 2 2\r");
  expect_error([&] { io::import_log(f, two_mapping(), two_joints()); }, f.string(), 1,
               "the lines end in CR alone (no LF anywhere): convert the line ends to LF or CR LF");
}

// A NUL byte in a field is shown escaped; the message does not stop at it.
TEST_F(Import, QuotesControlBytesEscaped) {
  const fs::path f = dir_ / "nul.txt";
  write_text(f, "0 0 0 0 0\n0.001 1 -0." + std::string(1, '\0') + "73 1 1\n");
  expect_error([&] { io::import_log(f, two_mapping(), two_joints()); }, f.string(), 2,
               "'-0.\\073' in column 3 is not a number");
  io::ImportMapping named;
  named.time = "t";
  named.q = "p1,p2";
  named.tau = "e1,e2";
  write_text(f,
             "t,p1,p\x01"
             "2,e1,e2\n0,0,0,0,0\n0.001,1,x,1,1\n");
  named.q =
      "p1,p\x01"
      "2";
  expect_error([&] { io::import_log(f, named, two_joints()); }, f.string(), 3, "'x' in 'p\\x012' (column 3)");
}

TEST_F(Import, MappingFileErrorsNameTheirLine) {
  const fs::path m = dir_ / "map.yaml";
  write_text(m, "time: t\nq: \"pos_*\"\ntau: [e1, e2]\nunits: {time: ms, angle: deg, torque_scale: 2}\nheader: yes\n");
  const io::ImportMapping read = io::read_import_mapping(m);
  EXPECT_EQ(read.tau, "e1,e2");
  EXPECT_EQ(read.time_unit, io::TimeUnit::ms);
  EXPECT_EQ(read.torque_scale, 2);
  EXPECT_EQ(read.header, io::HeaderRow::present);
  EXPECT_EQ(read.lines.at("tau"), 3);
  write_text(m, "time: t\nq: \"pos_*\"\ntau: e\nunits:\n  time: minutes\n");
  expect_error([&] { io::read_import_mapping(m); }, m.string(), 5, "units.time: 'minutes' is not one of s, ms, us, ns");
  write_text(m, "time: t\nqq: \"pos_*\"\n");
  expect_error([&] { io::read_import_mapping(m); }, m.string(), 2, "unknown key 'qq'");
  // A selector that does not fit names the mapping file's line in the message.
  write_text(m, "time: 1\nq: 2-4\ntau: 4-5\n");
  const fs::path f = dir_ / "data.txt";
  write_text(f, "0 0 0 0 0\n0.001 1 1 1 1\n");
  expect_error([&] { io::import_log(f, io::read_import_mapping(m), two_joints()); }, f.string(), 1,
               "q: '2-4' (" + m.string() + ":2): selects 3 columns");
}

// The sidecar key is optional: a measured log's sidecar is as before, an unknown value is refused.
TEST_F(Import, SidecarVelocityKey) {
  const fs::path input = dir_ / "two.txt";
  write_two(input, 50);
  io::ImportMapping m = two_mapping();
  io::Log log = io::import_log(input, m, two_joints()).log;
  log.meta.velocity = io::Velocity::measured;
  const fs::path csv = dir_ / "log.csv";
  io::write_log(csv, log);
  std::string sidecar = read_text(io::metadata_path(csv));
  EXPECT_EQ(sidecar.find("velocity"), std::string::npos) << sidecar;
  EXPECT_EQ(io::read_log(csv).meta.velocity, io::Velocity::measured);
  write_text(io::metadata_path(csv), sidecar + "velocity: guessed\n");
  const int line = static_cast<int>(std::count(sidecar.begin(), sidecar.end(), '\n')) + 1;
  expect_error([&] { io::read_log_metadata(csv); }, io::metadata_path(csv).string(), line,
               "velocity: 'guessed' is neither measured nor differentiated");
}
