// The log format: bit-for-bit round trips, tolerated layouts, and every rejection with its
// file and line.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "symoro/error.hpp"
#include "symoro/io/log.hpp"

namespace fs = std::filesystem;
using symoro::DataError;
using symoro::io::Log;
using symoro::io::metadata_path;
using symoro::io::read_log;
using symoro::io::write_log;

namespace {

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& p, const std::string& content) {
  std::ofstream out(p, std::ios::binary);
  out << content;
}

// Values that a careless writer would round or mangle.
const double awkward[] = {1e-300,
                          -0.0,
                          0.0,
                          0.1,
                          1.0 / 3.0,
                          -2.5e15,
                          1.7976931348623157e308,
                          -2.2250738585072014e-308,
                          4.9406564584124654e-324,  // smallest subnormal
                          9007199254740993.0,
                          123456789.123456789,
                          -1e22};

Eigen::MatrixXd random_matrix(std::mt19937_64& rng, int rows, int cols) {
  std::normal_distribution<double> normal(0.0, 3.0);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(awkward)) - 1);
  std::uniform_int_distribution<int> one_in_ten(0, 9);
  Eigen::MatrixXd m(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int k = 0; k < rows; ++k) m(k, j) = one_in_ten(rng) == 0 ? awkward[pick(rng)] : normal(rng);
  return m;
}

Log random_log(int samples, int joints, bool references, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Log log;
  log.meta.robot = "crane_x7";
  log.meta.trajectory = "AG02";
  log.meta.trial = 3;
  log.meta.seed = 18446744073709551615ull;
  log.meta.source = "twin";
  log.meta.sample_time = 0.001;
  for (int j = 0; j < joints; ++j) log.meta.joints.push_back("joint" + std::to_string(j + 1));
  log.meta.notes = "twin: friction x1.1, \"quoted\"\nsecond line";
  std::uniform_real_distribution<double> step(1e-7, 2e-3);
  log.time.resize(samples);
  double t = 12.345678901234567;
  for (int k = 0; k < samples; ++k) log.time[k] = (t += step(rng));
  log.q = random_matrix(rng, samples, joints);
  log.qd = random_matrix(rng, samples, joints);
  log.tau = random_matrix(rng, samples, joints);
  if (references) {
    log.q_ref = random_matrix(rng, samples, joints);
    log.qd_ref = random_matrix(rng, samples, joints);
    log.qdd_ref = random_matrix(rng, samples, joints);
  }
  return log;
}

void expect_same_bits(const Eigen::MatrixXd& read, const Eigen::MatrixXd& written, const char* what) {
  ASSERT_EQ(read.rows(), written.rows()) << what;
  ASSERT_EQ(read.cols(), written.cols()) << what;
  for (Eigen::Index j = 0; j < read.cols(); ++j)
    for (Eigen::Index k = 0; k < read.rows(); ++k)
      ASSERT_EQ(bits(read(k, j)), bits(written(k, j)))
          << what << "(" << k << ", " << j << "): read " << read(k, j) << ", wrote " << written(k, j);
}

void expect_same_metadata(const symoro::io::LogMetadata& read, const symoro::io::LogMetadata& written) {
  EXPECT_EQ(read.robot, written.robot);
  EXPECT_EQ(read.trajectory, written.trajectory);
  EXPECT_EQ(read.trial, written.trial);
  EXPECT_EQ(read.seed, written.seed);
  EXPECT_EQ(read.source, written.source);
  EXPECT_EQ(bits(read.sample_time), bits(written.sample_time));
  EXPECT_EQ(read.joints, written.joints);
  EXPECT_EQ(read.notes, written.notes);
}

// A sidecar for the hand-written CSVs below.
std::string sidecar(int samples, const std::string& source = "twin", int joints = 2) {
  std::string names;
  for (int j = 1; j <= joints; ++j) names += (j > 1 ? ", " : "") + std::string("j") + std::to_string(j);
  std::string units = "  time: s\n";
  if (source != "reference") units += "  q: rad\n  qd: rad/s\n  tau: N*m\n";
  units += "  q_ref: rad\n  qd_ref: rad/s\n  qdd_ref: rad/s^2\n";
  return "format: symoro-log 1\n"  // line 1
         "robot: crane_x7\n"       // 2
         "trajectory: AG02\n"      // 3
         "trial: 1\n"              // 4
         "seed: 7\n"               // 5
         "source: " +
         source +
         "\n"                    // 6
         "sample_time: 0.001\n"  // 7
         "samples: " +
         std::to_string(samples) +
         "\n"  // 8
         "joints: [" +
         names +
         "]\n"  // 9
         "units:\n" +
         units +  // 10, then one line per unit
         "notes: hand written\n";
}

const std::string header2 = "time,q1,q2,qd1,qd2,tau1,tau2\n";

class LogFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("symoro_test_io_log_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path path(const std::string& name) const { return dir_ / name; }

  // Writes "<name>.csv" and its sidecar as given; returns the CSV's path.
  fs::path files(const std::string& csv_text, const std::string& sidecar_text, const std::string& name = "log") {
    const fs::path csv = path(name + ".csv");
    write_text(csv, csv_text);
    write_text(metadata_path(csv), sidecar_text);
    return csv;
  }

  // Expects read_log(csv) to throw a DataError at `file`:`line` whose message contains `problem`.
  static void expect_rejected(const fs::path& csv, const fs::path& file, int line, const std::string& problem) {
    try {
      read_log(csv);
      FAIL() << "read_log accepted " << csv << "; expected: " << problem;
    } catch (const DataError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), file.string()) << what;
      EXPECT_EQ(e.line(), line) << what;
      const std::string location = file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": error: ";
      EXPECT_EQ(what.rfind(location, 0), 0u) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << "message: " << what << "\nexpected to contain: " << problem;
    }
  }

  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

// --- Round trips and accepted layouts ------------------------------------------------------

TEST_F(LogFiles, RoundTripIsBitForBit) {
  const Log written = random_log(500, 7, true, 1);
  const fs::path csv = path("AG02_1.csv");
  write_log(csv, written);
  const Log read = read_log(csv);
  expect_same_metadata(read.meta, written.meta);
  ASSERT_EQ(read.samples(), 500);
  ASSERT_EQ(read.joints(), 7);
  EXPECT_TRUE(read.has_references());
  for (int k = 0; k < read.samples(); ++k) ASSERT_EQ(bits(read.time[k]), bits(written.time[k])) << k;
  expect_same_bits(read.q, written.q, "q");
  expect_same_bits(read.qd, written.qd, "qd");
  expect_same_bits(read.tau, written.tau, "tau");
  expect_same_bits(read.q_ref, written.q_ref, "q_ref");
  expect_same_bits(read.qd_ref, written.qd_ref, "qd_ref");
  expect_same_bits(read.qdd_ref, written.qdd_ref, "qdd_ref");
}

TEST_F(LogFiles, EveryAwkwardValueSurvives) {
  Log written = random_log(static_cast<int>(std::size(awkward)), 1, false, 2);
  for (std::size_t k = 0; k < std::size(awkward); ++k) written.q(k, 0) = awkward[k];
  const fs::path csv = path("awkward.csv");
  write_log(csv, written);
  const Log read = read_log(csv);
  for (std::size_t k = 0; k < std::size(awkward); ++k) EXPECT_EQ(bits(read.q(k, 0)), bits(awkward[k])) << awkward[k];
  EXPECT_TRUE(std::signbit(read.q(1, 0)));  // -0.0 keeps its sign
  // Shortest forms, not 17-digit ones.
  const std::string text = read_text(csv);
  EXPECT_NE(text.find(",0.1,"), std::string::npos);
  EXPECT_NE(text.find(",1e-300,"), std::string::npos);
  EXPECT_NE(text.find(",-0,"), std::string::npos);
}

TEST_F(LogFiles, RoundTripWithoutReferences) {
  const Log written = random_log(50, 3, false, 3);
  const fs::path csv = path("plain.csv");
  write_log(csv, written);
  const Log read = read_log(csv);
  EXPECT_FALSE(read.has_references());
  EXPECT_EQ(read.q_ref.cols(), 0);
  EXPECT_EQ(read_text(csv).substr(0, read_text(csv).find('\n')), "time,q1,q2,q3,qd1,qd2,qd3,tau1,tau2,tau3");
  expect_same_bits(read.tau, written.tau, "tau");
}

TEST_F(LogFiles, ReferenceFileRoundTrip) {
  Log written = random_log(40, 2, true, 4);
  written.meta.source = "reference";
  written.meta.seed = 0;
  written.meta.trial = 0;
  written.q.resize(0, 0);
  written.qd.resize(0, 0);
  written.tau.resize(0, 0);
  const fs::path csv = path("AG02.csv");
  write_log(csv, written);
  const std::string text = read_text(csv);
  EXPECT_EQ(text.substr(0, text.find('\n')), "time,q_ref1,q_ref2,qd_ref1,qd_ref2,qdd_ref1,qdd_ref2");
  const std::string meta = read_text(metadata_path(csv));
  EXPECT_EQ(meta.find("tau"), std::string::npos) << meta;  // no units for absent groups

  const Log read = read_log(csv);
  expect_same_metadata(read.meta, written.meta);
  EXPECT_EQ(read.samples(), 40);
  EXPECT_EQ(read.q.cols(), 0);
  EXPECT_EQ(read.qd.cols(), 0);
  EXPECT_EQ(read.tau.cols(), 0);
  expect_same_bits(read.q_ref, written.q_ref, "q_ref");
  expect_same_bits(read.qd_ref, written.qd_ref, "qd_ref");
  expect_same_bits(read.qdd_ref, written.qdd_ref, "qdd_ref");
}

TEST_F(LogFiles, SidecarLayout) {
  const Log written = random_log(3, 2, false, 5);
  const fs::path csv = path("layout.csv");
  write_log(csv, written);
  EXPECT_EQ(metadata_path(csv), path("layout.meta.yaml"));
  const std::string meta = read_text(path("layout.meta.yaml"));
  EXPECT_EQ(meta.rfind("format: symoro-log 1\n", 0), 0u) << meta;
  EXPECT_NE(meta.find("samples: 3\n"), std::string::npos) << meta;
  EXPECT_NE(meta.find("sample_time: 0.001\n"), std::string::npos) << meta;
  EXPECT_NE(meta.find("seed: 18446744073709551615\n"), std::string::npos) << meta;
  EXPECT_NE(meta.find("tau: N*m"), std::string::npos) << meta;
  EXPECT_NE(meta.find("qd: rad/s"), std::string::npos) << meta;
  EXPECT_EQ(meta.find("q_ref"), std::string::npos) << meta;
  EXPECT_EQ(symoro::io::read_log_metadata(csv).joints, written.meta.joints);
}

TEST_F(LogFiles, MetadataThatLooksLikeOtherYamlTypesStaysText) {
  Log written = random_log(2, 2, false, 6);
  written.meta.robot = "null";
  written.meta.trajectory = "123";
  written.meta.joints = {"yes", "~"};
  written.meta.notes = "";
  const fs::path csv = path("strings.csv");
  write_log(csv, written);
  expect_same_metadata(read_log(csv).meta, written.meta);
}

TEST_F(LogFiles, ColumnsAreMatchedByName) {
  const fs::path csv = files(
      "tau2,qd1,time,q2,tau1,q1,qd2\n"
      "6,3,0.5,2,5,1,4\n"
      "16,13,0.75,12,15,11,14\n",
      sidecar(2));
  const Log log = read_log(csv);
  ASSERT_EQ(log.samples(), 2);
  ASSERT_EQ(log.joints(), 2);
  EXPECT_EQ(log.time[0], 0.5);
  EXPECT_EQ(log.time[1], 0.75);
  EXPECT_EQ(log.q(0, 0), 1);
  EXPECT_EQ(log.q(0, 1), 2);
  EXPECT_EQ(log.qd(0, 0), 3);
  EXPECT_EQ(log.qd(0, 1), 4);
  EXPECT_EQ(log.tau(0, 0), 5);
  EXPECT_EQ(log.tau(0, 1), 6);
  EXPECT_EQ(log.q(1, 1), 12);
  EXPECT_EQ(log.tau(1, 1), 16);
  EXPECT_EQ(log.meta.joints, (std::vector<std::string>{"j1", "j2"}));
  EXPECT_EQ(log.meta.notes, "hand written");
}

TEST_F(LogFiles, AcceptsCrLfSpacesAndByteOrderMark) {
  const fs::path csv = files(
      "\xEF\xBB\xBFtime, q1,q2 ,qd1,qd2,tau1,tau2\r\n"
      "0, 1 ,2,3,4,5,6\r\n"
      "1e-3,1,2,3,4,5,-6.5e-1\r\n",
      sidecar(2));
  const Log log = read_log(csv);
  ASSERT_EQ(log.samples(), 2);
  EXPECT_EQ(log.time[1], 1e-3);
  EXPECT_EQ(log.q(0, 0), 1);
  EXPECT_EQ(log.tau(1, 1), -0.65);
}

TEST_F(LogFiles, OverwritingALogReplacesIt) {
  const fs::path csv = path("replace.csv");
  write_log(csv, random_log(100, 7, true, 7));
  const Log second = random_log(10, 2, false, 8);
  write_log(csv, second);
  const Log read = read_log(csv);
  EXPECT_EQ(read.samples(), 10);
  EXPECT_EQ(read.joints(), 2);
  EXPECT_FALSE(read.has_references());
  expect_same_bits(read.q, second.q, "q");
  EXPECT_EQ(entries(), (std::vector<std::string>{"replace.csv", "replace.meta.yaml"}));
}

// --- The writer's checks and atomicity -----------------------------------------------------

TEST_F(LogFiles, WriterRejectsInconsistentLogs) {
  const fs::path csv = path("bad.csv");
  const std::vector<std::pair<std::function<void(Log&)>, std::string>> cases = {
      {[](Log& l) { l.q.conservativeResize(l.q.rows() - 1, Eigen::NoChange); },
       "q is 9 x 2 but the log has 10 samples"},
      {[](Log& l) { l.tau.conservativeResize(Eigen::NoChange, 3); }, "tau is 10 x 3"},
      {[](Log& l) { l.meta.joints.push_back("j3"); }, "q is 10 x 2 but the log has 10 samples of 3 joints"},
      {[](Log& l) { l.qd(4, 1) = std::nan(""); }, "qd2 at sample 5 is nan"},
      {[](Log& l) { l.tau(0, 0) = -std::numeric_limits<double>::infinity(); }, "tau1 at sample 1 is -inf"},
      {[](Log& l) { l.time[6] = l.time[5]; }, "time does not increase strictly: sample 6"},
      {[](Log& l) { l.time[9] = std::numeric_limits<double>::infinity(); }, "time at sample 10 is inf"},
      {[](Log& l) { l.q_ref = l.q; }, "q_ref, qd_ref and qdd_ref must be all present or all empty"},
      {[](Log& l) { l.meta.source = "simulation"; }, "unknown source 'simulation'"},
      {[](Log& l) { l.meta.joints[1] = l.meta.joints[0]; }, "joint name 'joint1' appears twice"},
      {[](Log& l) { l.meta.sample_time = 0; }, "sample_time 0 is not a positive finite number"},
      {[](Log& l) { l.meta.robot.clear(); }, "the robot name is empty"},
      {[](Log& l) { l.meta.source = "reference"; }, "a reference log has no q columns"},
      {[](Log& l) {
         l.time.resize(0);
         l.q.resize(0, 2);
         l.qd.resize(0, 2);
         l.tau.resize(0, 2);
       },
       "the log has no samples"},
  };
  for (const auto& [spoil, problem] : cases) {
    Log log = random_log(10, 2, false, 9);
    spoil(log);
    try {
      write_log(csv, log);
      ADD_FAILURE() << "write_log accepted a log with: " << problem;
    } catch (const DataError& e) {
      EXPECT_EQ(e.file(), csv.string());
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what() << "\nexpected: " << problem;
    }
    EXPECT_TRUE(entries().empty());
  }
}

TEST_F(LogFiles, FailedWriteLeavesTheExistingLogAndNoTemporaryFiles) {
  const fs::path csv = path("keep.csv");
  write_log(csv, random_log(20, 2, false, 10));
  const std::string csv_before = read_text(csv);
  const std::string meta_before = read_text(metadata_path(csv));

  Log bad = random_log(30, 2, false, 11);
  bad.q(29, 1) = std::nan("");
  EXPECT_THROW(write_log(csv, bad), DataError);
  EXPECT_EQ(read_text(csv), csv_before);
  EXPECT_EQ(read_text(metadata_path(csv)), meta_before);
  EXPECT_EQ(entries(), (std::vector<std::string>{"keep.csv", "keep.meta.yaml"}));
  EXPECT_EQ(read_log(csv).samples(), 20);
}

TEST_F(LogFiles, UnwritableTargetThrowsAndLeavesNothing) {
  const fs::path csv = path("no_such_dir") / "log.csv";
  try {
    write_log(csv, random_log(5, 2, false, 12));
    FAIL() << "wrote into a missing directory";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("log.csv"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(LogFiles, FailedSidecarWriteLeavesNoTemporaryFiles) {
  // A directory where the sidecar goes: the CSV is written, the sidecar's rename fails.
  const fs::path csv = path("blocked.csv");
  fs::create_directories(path("blocked.meta.yaml") / "occupied");
  EXPECT_THROW(write_log(csv, random_log(5, 2, false, 13)), DataError);
  EXPECT_EQ(entries(), (std::vector<std::string>{"blocked.csv", "blocked.meta.yaml"}));
  EXPECT_TRUE(fs::is_directory(path("blocked.meta.yaml")));
}

// --- The reader's rejections: CSV ----------------------------------------------------------

TEST_F(LogFiles, RejectsMissingCsv) {
  write_text(path("gone.meta.yaml"), sidecar(1));
  expect_rejected(path("gone.csv"), path("gone.csv"), 0, "cannot open the log");
}

TEST_F(LogFiles, RejectsMissingColumn) {
  const fs::path csv = files("time,q1,q2,qd1,qd2,tau1\n0,1,2,3,4,5\n", sidecar(1));
  expect_rejected(csv, csv, 1, "missing column 'tau2' (the sidecar lists 2 joints)");
}

TEST_F(LogFiles, RejectsMissingTime) {
  const fs::path csv = files("q1,q2,qd1,qd2,tau1,tau2\n1,2,3,4,5,6\n", sidecar(1));
  expect_rejected(csv, csv, 1, "missing column 'time'");
}

TEST_F(LogFiles, RejectsDuplicateColumn) {
  const fs::path csv = files("time,q1,q2,q1,qd1,qd2,tau1,tau2\n0,1,2,1,3,4,5,6\n", sidecar(1));
  expect_rejected(csv, csv, 1, "duplicate column 'q1' (columns 2 and 4)");
}

TEST_F(LogFiles, RejectsUnknownColumn) {
  const fs::path csv = files("time,q1,q2,qd1,qd2,tau1,tau2,current1\n0,1,2,3,4,5,6,7\n", sidecar(1));
  expect_rejected(csv, csv, 1, "unknown column 'current1'");
}

TEST_F(LogFiles, RejectsZeroPaddedJointNumber) {
  const fs::path csv = files("time,q01,q2,qd1,qd2,tau1,tau2\n0,1,2,3,4,5,6\n", sidecar(1));
  expect_rejected(csv, csv, 1, "unknown column 'q01'");
}

TEST_F(LogFiles, RejectsCsvWithMoreJointsThanTheSidecar) {
  const fs::path csv = files("time,q1,q2,q3,qd1,qd2,qd3,tau1,tau2,tau3\n0,1,2,3,4,5,6,7,8,9\n", sidecar(1));
  expect_rejected(csv, csv, 1, "unknown column 'q3': joint 3 does not exist, the sidecar lists 2 joints");
}

TEST_F(LogFiles, RejectsSidecarWithMoreJointsThanTheCsv) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar(1, "twin", 3));
  expect_rejected(csv, csv, 1, "missing columns 'q3', 'qd3', 'tau3' (the sidecar lists 3 joints)");
}

TEST_F(LogFiles, RejectsPartialReferenceGroup) {
  const fs::path csv = files(
      "time,q1,q2,qd1,qd2,tau1,tau2,q_ref1,q_ref2,qd_ref1,qd_ref2,qdd_ref1\n"
      "0,1,2,3,4,5,6,7,8,9,10,11\n",
      sidecar(1));
  expect_rejected(csv, csv, 1, "partial reference group: missing column 'qdd_ref2'");
}

TEST_F(LogFiles, RejectsMeasuredColumnsInAReferenceFile) {
  const fs::path csv =
      files("time,q_ref1,q_ref2,qd_ref1,qd_ref2,qdd_ref1,qdd_ref2,q1\n0,1,2,3,4,5,6,7\n", sidecar(1, "reference"));
  expect_rejected(csv, csv, 1, "unknown column 'q1' in a reference file");
}

TEST_F(LogFiles, RejectsReferenceFileWithoutReferences) {
  const fs::path csv = files("time,q_ref1,q_ref2\n0,1,2\n", sidecar(1, "reference"));
  expect_rejected(csv, csv, 1, "missing columns 'qd_ref1', 'qd_ref2', 'qdd_ref1', 'qdd_ref2' in a reference file");
}

TEST_F(LogFiles, RejectsRowWithTooFewFields) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,2,3,4,5\n2,1,2,3,4,5,6\n", sidecar(3));
  expect_rejected(csv, csv, 3, "row has 6 fields, the header has 7");
}

TEST_F(LogFiles, RejectsRowWithTooManyFields) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n2,1,2,3,4,5,6,7,8\n", sidecar(3));
  expect_rejected(csv, csv, 4, "row has 9 fields, the header has 7");
}

TEST_F(LogFiles, RejectsTrailingComma) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6,\n", sidecar(1));
  expect_rejected(csv, csv, 2, "row has 8 fields, the header has 7");
}

// A writer killed mid-row leaves a last line without its newline. Cut inside a number, the rest
// may still parse ("-0" of "-0.737", "1e" does not, "-0." does): every such file is refused at
// its last line, whatever the cut left, even a row with all its fields.
TEST_F(LogFiles, RejectsALastLineCutWithoutNewline) {
  for (const std::string cut : {"1,1,2,3", "1,1,2,3,4,5,-0", "1,1,2,3,4,5,-0.", "1,1,2,3,4,5,-", "1,1,2,3,4,5,1e",
                                "1,1,2,3,4,5,6", "1,1,2,3,4,5,6\r"}) {
    SCOPED_TRACE(cut);
    const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n" + cut, sidecar(2));
    expect_rejected(csv, csv, 3, "the last line has no newline at its end: the file was cut while it was written");
  }
  // The header alone, cut.
  const fs::path csv = files("time,q1,q2,qd1,qd2,ta", sidecar(0));
  expect_rejected(csv, csv, 1, "the last line has no newline at its end");
}

// A NUL byte in a field: the message shows it escaped and goes on past it.
TEST_F(LogFiles, QuotesControlBytesEscaped) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,2,-0." + std::string(1, '\0') + "7x,4,5,6\n", sidecar(2));
  expect_rejected(csv, csv, 3, "'-0.\\07x' in column 'qd1' is not a number");
  const fs::path header =
      files("time,q1,q\x01" + std::string(1, '\0') + "2,qd1,qd2,tau1,tau2\n0,1,2,3,4,5,6\n", sidecar(1));
  expect_rejected(header, header, 1, "unknown column 'q\\x01\\02'");
}

TEST_F(LogFiles, RejectsEmptyField) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,,3,4,5,6\n", sidecar(2));
  expect_rejected(csv, csv, 3, "empty field in column 'q2'");
}

TEST_F(LogFiles, RejectsText) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n2,1,2,3,fast,5,6\n", sidecar(3));
  expect_rejected(csv, csv, 4, "'fast' in column 'qd2' is not a number");
}

TEST_F(LogFiles, RejectsNumberWithTrailingText) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6.5.1\n", sidecar(1));
  expect_rejected(csv, csv, 2, "'6.5.1' in column 'tau2' is not a number");
}

TEST_F(LogFiles, RejectsNaN) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,nan,2,3,4,5,6\n", sidecar(2));
  expect_rejected(csv, csv, 3, "column 'q1' holds 'nan', not a finite number");
}

TEST_F(LogFiles, RejectsInfinity) {
  const fs::path csv = files(header2 + "0,1,2,3,4,-inf,6\n", sidecar(1));
  expect_rejected(csv, csv, 2, "column 'tau1' holds '-inf', not a finite number");
}

TEST_F(LogFiles, RejectsNumberOutOfRange) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,1e999\n", sidecar(1));
  expect_rejected(csv, csv, 2, "'1e999' in column 'tau2' is out of the range of a double");
}

TEST_F(LogFiles, RejectsTimeGoingBack) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n0.002,1,2,3,4,5,6\n0.001,1,2,3,4,5,6\n", sidecar(3));
  expect_rejected(csv, csv, 4, "time does not increase strictly: 0.001 s here, 0.002 s on line 3 before it");
}

TEST_F(LogFiles, RejectsRepeatedTime) {
  const fs::path csv = files(header2 + "0.5,1,2,3,4,5,6\n0.5,1,2,3,4,5,6\n", sidecar(2));
  expect_rejected(csv, csv, 3, "0.5 s here, 0.5 s on line 2 before it");
}

TEST_F(LogFiles, RejectsBlankLineInTheMiddle) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n\n1,1,2,3,4,5,6\n", sidecar(2));
  expect_rejected(csv, csv, 3, "blank line");
}

TEST_F(LogFiles, RejectsBlankLineAtTheEnd) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\r\n\r\n", sidecar(1));
  expect_rejected(csv, csv, 3, "blank line");
}

TEST_F(LogFiles, RejectsHeaderOnly) {
  const fs::path csv = files(header2, sidecar(1));
  expect_rejected(csv, csv, 2, "no data rows after the header");
}

TEST_F(LogFiles, RejectsEmptyFile) {
  const fs::path csv = files("", sidecar(1));
  expect_rejected(csv, csv, 1, "no header row");
}

TEST_F(LogFiles, RejectsCsvShorterThanTheSidecarSays) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n", sidecar(3));
  expect_rejected(
      csv, csv, 0,
      "the CSV has 2 samples but its sidecar (" + metadata_path(csv).string() + ":8) says samples: 3 (truncated CSV?)");
}

TEST_F(LogFiles, RejectsCsvLongerThanTheSidecarSays) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n2,1,2,3,4,5,6\n", sidecar(2));
  expect_rejected(csv, csv, 4, "the CSV has 3 samples but its sidecar");
}

// --- The reader's rejections: sidecar ------------------------------------------------------

// The valid sidecar with line `line` (1-based) replaced by `text`.
std::string sidecar_with_line(int line, const std::string& text) {
  std::istringstream in(sidecar(1));
  std::string out, l;
  for (int n = 1; std::getline(in, l); ++n) out += (n == line ? text : l) + "\n";
  return out;
}

// A control byte in a sidecar's number is shown escaped, not sent raw to the terminal.
TEST_F(LogFiles, SidecarNumbersAreQuotedEscaped) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(8, "samples: 1\x01x"));
  expect_rejected(csv, metadata_path(csv), 8, "samples: expected a whole number, got '1\\x01x'");
  const fs::path time = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(7, "sample_time: 0.001\x1b[2J"), "t");
  expect_rejected(time, metadata_path(time), 7, "sample_time: expected a finite number, got '0.001\\x1b[2J'");
}

TEST_F(LogFiles, RejectsMissingSidecar) {
  const fs::path csv = path("alone.csv");
  write_text(csv, header2 + "0,1,2,3,4,5,6\n");
  expect_rejected(csv, path("alone.meta.yaml"), 0, "missing or unreadable metadata sidecar");
}

TEST_F(LogFiles, RejectsSidecarWithBadYaml) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(9, "joints: [j1, j2"));
  try {
    read_log(csv);
    FAIL() << "accepted a sidecar with an unclosed list";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), metadata_path(csv).string());
    EXPECT_GE(e.line(), 9) << e.what();  // yaml-cpp notices at the list or just after it
    EXPECT_LE(e.line(), 10) << e.what();
    EXPECT_NE(std::string(e.what()).find("YAML syntax error: end of sequence flow not found"), std::string::npos)
        << e.what();
  }
}

TEST_F(LogFiles, RejectsSidecarWithTabIndentation) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(4, "trial: 1\n\tbad: ["));
  try {
    read_log(csv);
    FAIL() << "accepted broken YAML";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), metadata_path(csv).string());
    EXPECT_EQ(e.line(), 5) << e.what();
  }
}

TEST_F(LogFiles, RejectsSidecarWithoutAKey) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(8, "# samples removed"));
  expect_rejected(csv, metadata_path(csv), 0, "the metadata sidecar has no 'samples'");
}

TEST_F(LogFiles, RejectsSidecarWithUnknownKey) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(3, "trajectroy: AG02"));
  expect_rejected(csv, metadata_path(csv), 3,
                  "unknown key 'trajectroy' in the metadata sidecar; did you mean 'trajectory'?");
}

TEST_F(LogFiles, RejectsSidecarWithUnknownUnitsKey) {
  std::string text = sidecar(1);
  text.replace(text.find("  qd: rad/s"), 11, "  qdd: rad/s");
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", text);
  expect_rejected(csv, metadata_path(csv), 13, "unknown key 'qdd' in units; did you mean 'qd'?");
}

// yaml-cpp reads a value whose closing quote is missing as text to the end of the file: the
// keys after it would vanish into the trajectory name.
TEST_F(LogFiles, RejectsSidecarWithAnUnclosedQuote) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(3, "trajectory: \"AG02"));
  try {
    read_log(csv);
    FAIL() << "accepted a sidecar with an unclosed quote";
  } catch (const DataError& e) {
    EXPECT_EQ(e.line(), 3) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(metadata_path(csv).string() + ":3:13: error: YAML syntax error: ", 0), 0u)
        << e.what();
  }
}

TEST_F(LogFiles, RejectsSidecarWithRepeatedKey) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(3, "robot: other"));
  expect_rejected(csv, metadata_path(csv), 3, "key 'robot' appears twice");
}

TEST_F(LogFiles, RejectsOtherFormatVersion) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(1, "format: symoro-log 2"));
  expect_rejected(csv, metadata_path(csv), 1, "unsupported log format version 'symoro-log 2'");
}

TEST_F(LogFiles, RejectsUnknownSource) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(6, "source: simulator"));
  expect_rejected(csv, metadata_path(csv), 6, "source: unknown source 'simulator'");
}

TEST_F(LogFiles, RejectsIllTypedValues) {
  const fs::path trial = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(4, "trial: first"), "a");
  expect_rejected(trial, metadata_path(trial), 4, "trial: expected a whole number, got 'first'");
  const fs::path seed = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(5, "seed: -1"), "b");
  expect_rejected(seed, metadata_path(seed), 5, "seed: expected a whole number >= 0, got '-1'");
  const fs::path dt = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(7, "sample_time: -0.001"), "c");
  expect_rejected(dt, metadata_path(dt), 7, "sample_time: -0.001 s is not positive");
  const fs::path samples = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(8, "samples: [1]"), "d");
  expect_rejected(samples, metadata_path(samples), 8, "samples: expected a single value");
}

TEST_F(LogFiles, RejectsNonSiUnit) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(12, "  q: deg"));
  expect_rejected(csv, metadata_path(csv), 12, "units: q is in 'deg', but a log holds SI values: expected 'rad'");
}

TEST_F(LogFiles, RejectsMissingUnitOfAColumnGroup) {
  const fs::path csv = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(14, "  # tau left out"));
  expect_rejected(csv, metadata_path(csv), 10, "units: no unit for tau (expected 'N*m')");
}

TEST_F(LogFiles, RejectsSidecarJointListProblems) {
  const fs::path twice = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(9, "joints: [j1, j1]"), "a");
  expect_rejected(twice, metadata_path(twice), 9, "joints: joint name 'j1' appears twice");
  const fs::path empty = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(9, "joints: []"), "b");
  expect_rejected(empty, metadata_path(empty), 9, "joints: expected a non-empty list of joint names");
  const fs::path nested = files(header2 + "0,1,2,3,4,5,6\n", sidecar_with_line(9, "joints: [j1, [j2]]"), "c");
  expect_rejected(nested, metadata_path(nested), 9, "joints: expected a single value");
}

// --- Speed (run with --gtest_also_run_disabled_tests; prints, asserts nothing about time) ---

TEST_F(LogFiles, DISABLED_Speed110000x49) {
  const Log log = random_log(110000, 8, true, 14);  // 1 + 6 x 8 = 49 columns
  const fs::path csv = path("speed.csv");
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  write_log(csv, log);
  const auto t1 = clock::now();
  const Log read = read_log(csv);
  const auto t2 = clock::now();
  const double mb = static_cast<double>(fs::file_size(csv)) / 1e6;
  std::cout << "110000 x 49 log, " << mb << " MB: write " << std::chrono::duration<double>(t1 - t0).count()
            << " s, read " << std::chrono::duration<double>(t2 - t1).count() << " s\n";
  expect_same_bits(read.qdd_ref, log.qdd_ref, "qdd_ref");
}

}  // namespace
