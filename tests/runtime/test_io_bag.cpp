// dynid import of ROS 2 bags (io/import_bag.hpp) on bags written by an independent writer: the
// MCAP project's TypeScript writer and the ROS 2 CDR serializer from npm (tests/bags/
// write_bag.mjs, installed by ctest's fixture bags.npm). The logs are synthesized here: a smooth
// motion of the RX-90 and of CRANE-X7, with the torque of random physical links (the importer is
// told nothing of them) and a gripper's joint that is no robot joint. Checked: every value and
// stamp arrives bit for bit (lz4, zstd, uncompressed; chunked or not; other topics beside; two
// publishers; a bag folder of two files), partial and duplicate messages, motor current times
// torque constants, receive time, a file cut short, and clear errors naming the bag.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "symoro/error.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/import_bag.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
namespace io = symoro::io;

// One JointState message of the spec.
struct Msg {
  std::int64_t stamp_ns = 0, receive_ns = 0;
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
  std::string topic = "/joint_states";
};

std::string numbers(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{:.17g}", i ? "," : "", v[i]);
  return s + "]";
}

// Writes the bag with the independent writer; `extra` adds spec keys (compression, chunked, ...).
void write_bag(const std::vector<Msg>& messages, const std::string& where, const std::string& extra,
               bool other_topic = true) {
  // node, and the writer the fixture bags.npm installs (tests/runtime/CMakeLists.txt).
  const char* node = SYMORO_NODE;
  const char* writer = SYMORO_BAG_WRITER;
  ASSERT_TRUE(fs::exists(writer)) << writer << " is installed by the ctest fixture bags.npm (ctest -R bags.npm)";
  std::string spec = "{" + where + "," + extra + ",\"messages\":[";
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const Msg& m = messages[i];
    std::string names;
    for (const auto& n : m.name) names += (names.empty() ? "\"" : ",\"") + n + "\"";
    spec += fmt::format(
        "{}{{\"topic\":\"{}\",\"log_time_ns\":\"{}\",\"stamp_sec\":{},\"stamp_nanosec\":{},\"frame_id\":\"\","
        "\"name\":[{}],\"position\":{},\"velocity\":{},\"effort\":{}}}",
        i ? "," : "", m.topic, m.receive_ns, m.stamp_ns / 1000000000, m.stamp_ns % 1000000000, names,
        numbers(m.position), numbers(m.velocity), numbers(m.effort));
    if (other_topic && i % 50 == 7)
      spec += fmt::format(
          ",{{\"topic\":\"/rosout_like\",\"type\":\"std_msgs/msg/String\",\"log_time_ns\":\"{}\","
          "\"data\":\"status {}\"}}",
          m.receive_ns, i);
  }
  spec += "]}";
  // One spec per test: ctest runs the tests as processes side by side.
  const std::string spec_file =
      ::testing::TempDir() + "/" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".json";
  std::ofstream(spec_file) << spec;
  const std::string cmd = fmt::format("'{}' '{}' '{}'", node, writer, spec_file);
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

// A smooth motion of `Model` at 1 kHz with the torque of random links, as the driver publishes
// it: the robot's joints and a gripper joint, in an order of the driver's own.
template <class Model>
struct Motion {
  static constexpr int n = Model::nq;
  std::vector<std::string> names;
  Eigen::MatrixXd q, qd, tau;
  std::vector<std::int64_t> stamps;

  explicit Motion(int samples, unsigned seed) {
    symoro::test::Random rng(seed);
    const auto phi = Model::base_from_standard(symoro::test::random_standard_parameters<Model>(rng).s);
    q.resize(samples, n);
    qd.resize(samples, n);
    tau.resize(samples, n);
    for (const auto& j : Model::joints) names.emplace_back(j.name);
    for (int k = 0; k < samples; ++k) {
      const double t = 0.001 * k;
      Eigen::Matrix<double, n, 1> a, b, c;
      for (int j = 0; j < n; ++j) {
        const double w = 1.3 + 0.4 * j;
        a(j) = 0.4 * std::sin(w * t + j);
        b(j) = 0.4 * w * std::cos(w * t + j);
        c(j) = -0.4 * w * w * std::sin(w * t + j);
      }
      q.row(k) = a.transpose();
      qd.row(k) = b.transpose();
      tau.row(k) = Model::inverse_dynamics(a, b, c, phi).transpose();
      // Stamps of a real clock: 1 ms apart, from a time of day, with a few microseconds of jitter.
      stamps.push_back(1764400000123456789LL + 1000000LL * k + 1000LL * ((k * 7) % 5));
    }
  }

  // One message per sample: the joints reversed, a gripper joint among them.
  std::vector<Msg> messages(bool velocity = true) const {
    std::vector<Msg> out;
    for (int k = 0; k < q.rows(); ++k) {
      Msg m;
      m.stamp_ns = stamps[static_cast<std::size_t>(k)];
      m.receive_ns = m.stamp_ns + 250000 + 1000 * (k % 3);
      for (int j = n - 1; j >= 0; --j) {
        m.name.push_back(names[static_cast<std::size_t>(j)]);
        m.position.push_back(q(k, j));
        if (velocity) m.velocity.push_back(qd(k, j));
        m.effort.push_back(tau(k, j));
        if (j == 1) {
          m.name.push_back("gripper_finger_joint");
          m.position.push_back(0.01);
          if (velocity) m.velocity.push_back(0);
          m.effort.push_back(0.5);
        }
      }
      out.push_back(std::move(m));
    }
    return out;
  }
};

template <class Model>
io::ImportTarget target_of() {
  io::ImportTarget t;
  t.robot = Model::robot_name;
  for (const auto& j : Model::joints) {
    t.joints.emplace_back(j.name);
    t.lower.push_back(j.lower);
    t.upper.push_back(j.upper);
  }
  return t;
}

std::string bag_path(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / "bags";
  fs::create_directories(dir);
  fs::remove_all(dir / name);
  return (dir / name).string();
}

template <class Model>
void expect_exact(const io::ImportedLog& got, const Motion<Model>& m, bool velocity = true) {
  const io::Log& log = got.log;
  ASSERT_EQ(log.samples(), m.q.rows());
  for (Eigen::Index k = 0; k < log.samples(); ++k)
    ASSERT_EQ(log.time(k), static_cast<double>(m.stamps[static_cast<std::size_t>(k)] - m.stamps[0]) * 1e-9) << k;
  EXPECT_EQ(log.q, m.q);
  EXPECT_EQ(log.tau, m.tau);
  if (velocity) EXPECT_EQ(log.qd, m.qd);
  EXPECT_EQ(log.meta.velocity, velocity ? io::Velocity::measured : io::Velocity::differentiated);
  // The median step of stamps 1 ms apart with 0-4 us of jitter, to the microsecond.
  EXPECT_NEAR(log.meta.sample_time, 0.001, 3e-6);
}

using Rx90 = symoro::rx90::Model;
using Crane = symoro::crane_x7::Model;

TEST(ImportBag, EveryValueArrivesBitForBitInEachCompressionChunkedOrNot) {
  const Motion<Rx90> m(1500, 1);
  for (const char* kind :
       {"\"compression\":\"lz4\",\"chunked\":true,\"chunk_size\":65536", "\"compression\":\"zstd\",\"chunked\":true",
        "\"compression\":\"none\",\"chunked\":false", "\"compression\":\"none\",\"chunked\":true"}) {
    const std::string out = bag_path("rx90.mcap");
    write_bag(m.messages(), "\"out\":\"" + out + "\"", kind);
    const io::ImportedLog got = io::import_bag(out, {}, target_of<Rx90>());
    SCOPED_TRACE(kind);
    expect_exact(got, m);
    EXPECT_EQ(got.rows, 1500);
    EXPECT_EQ(got.log.meta.joints[0], Rx90::joints[0].name);
    bool listed = false;
    for (const auto& r : got.remarks) listed = listed || r.find("gripper_finger_joint") != std::string::npos;
    EXPECT_TRUE(listed) << "the ignored gripper joint is said";
  }
}

TEST(ImportBag, TwoPublishersOfOneStampMakeOneRowAndAPartialStampIsLeftOutAndCounted) {
  const Motion<Crane> m(800, 2);
  std::vector<Msg> split;
  for (const Msg& whole : m.messages()) {
    Msg arm = whole, hand = whole;  // the hand (joint 8) from another publisher, same stamp
    arm.name.clear(), arm.position.clear(), arm.velocity.clear(), arm.effort.clear();
    hand.name.clear(), hand.position.clear(), hand.velocity.clear(), hand.effort.clear();
    for (std::size_t i = 0; i < whole.name.size(); ++i) {
      Msg& to = whole.name[i] == "hand" ? hand : arm;
      to.name.push_back(whole.name[i]);
      to.position.push_back(whole.position[i]);
      to.velocity.push_back(whole.velocity[i]);
      to.effort.push_back(whole.effort[i]);
    }
    hand.receive_ns += 40000;
    split.push_back(hand);  // before the arm's: order within a stamp does not matter
    split.push_back(arm);
  }
  // One stamp's hand message lost (a partial row), one arm message recorded twice (a duplicate).
  split.erase(split.begin() + 2 * 300);
  split.insert(split.begin() + 2 * 500, split[2 * 500]);
  const std::string out = bag_path("crane.mcap");
  write_bag(split, "\"out\":\"" + out + "\"", "\"compression\":\"zstd\",\"chunked\":true");
  const io::ImportedLog got = io::import_bag(out, {}, target_of<Crane>());
  ASSERT_EQ(got.log.samples(), 799);
  EXPECT_EQ(got.duplicate_lines.size(), 1u);
  Eigen::Index k = 0;
  for (Eigen::Index r = 0; r < m.q.rows(); ++r) {
    if (r == 300) continue;
    ASSERT_EQ(got.log.q.row(k), m.q.row(r)) << r;
    ASSERT_EQ(got.log.tau.row(k), m.tau.row(r)) << r;
    ++k;
  }
  bool said = false;
  for (const auto& r : got.remarks)
    said = said || r.find("1 partial stamps left out (joints missing most: hand") == 0 ||
           r.find("1 partial stamps left out") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(ImportBag, MotorCurrentTimesTorqueConstantsAndVelocityDifferentiatedWhenAbsent) {
  const Motion<Crane> m(600, 3);
  std::vector<Msg> msgs = m.messages(false);
  const std::vector<double> kt = {2.3179, 3.1317, 2.3179, 2.3179, 2.3179, 2.3179, 2.3179, 2.3179};
  for (Msg& msg : msgs)
    for (std::size_t i = 0; i < msg.name.size(); ++i)
      for (int j = 0; j < Crane::nq; ++j)
        if (msg.name[i] == Crane::joints[static_cast<std::size_t>(j)].name)
          msg.effort[i] /= kt[static_cast<std::size_t>(j)];
  const std::string out = bag_path("current.mcap");
  write_bag(msgs, "\"out\":\"" + out + "\"", "\"compression\":\"lz4\",\"chunked\":true");
  io::BagSettings s;
  s.effort = io::EffortKind::current;
  s.torque_constants = kt;
  const io::ImportedLog got = io::import_bag(out, s, target_of<Crane>());
  EXPECT_LT((got.log.tau - m.tau).cwiseAbs().maxCoeff(), 1e-12 * m.tau.cwiseAbs().maxCoeff());
  EXPECT_EQ(got.log.meta.velocity, io::Velocity::differentiated);
  // Differences over stamps that carry up to 4 us of jitter while q was sampled on the exact 1 ms
  // grid: off by up to |qd| 4 us / 1 ms (0.4 %), 6.6e-3 rad/s at these joints' 1.65 rad/s.
  EXPECT_LT((got.log.qd - m.qd).middleRows(1, 598).cwiseAbs().maxCoeff(), 7e-3);
  EXPECT_NE(got.log.meta.notes.find("motor current (A) times the torque constants"), std::string::npos);
}

TEST(ImportBag, ABagFolderOfTwoFilesReadsAsOneRun) {
  const Motion<Rx90> m(1200, 4);
  const std::string dir = bag_path("rosbag2_run");
  write_bag(m.messages(), "\"bag_folder\":{\"dir\":\"" + dir + "\",\"files\":[0,700]}",
            "\"compression\":\"zstd\",\"chunked\":true");
  ASSERT_EQ(io::bag_files(dir).size(), 2u);
  expect_exact(io::import_bag(dir, {}, target_of<Rx90>()), m);
  // And through the dataset import, split 70/30.
  io::DatasetImport di;
  di.target = target_of<Rx90>();
  di.inputs.push_back({dir, "run", false});
  di.split = 0.7;
  const std::string ds = bag_path("dataset");
  const io::DatasetImportResult r = io::import_dataset(ds, di);
  ASSERT_EQ(r.runs.size(), 2u);
  const io::Log back = io::read_log(fs::path(ds) / "run.csv");
  EXPECT_EQ(back.samples(), 1200);
  EXPECT_LT((back.q - m.q).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ImportBag, AFileCutShortGivesTheMessagesBeforeTheCutAndSaysSo) {
  const Motion<Rx90> m(2000, 5);
  const std::string out = bag_path("cut.mcap");
  write_bag(m.messages(), "\"out\":\"" + out + "\"", "\"compression\":\"lz4\",\"chunked\":true,\"chunk_size\":32768");
  const auto size = fs::file_size(out);
  fs::resize_file(out, size * 6 / 10);
  const io::ImportedLog got = io::import_bag(out, {}, target_of<Rx90>());
  EXPECT_GT(got.log.samples(), 400);
  EXPECT_LT(got.log.samples(), 2000);
  EXPECT_EQ(got.log.q, m.q.topRows(got.log.samples()));
  bool said = false;
  for (const auto& r : got.remarks) said = said || r.find("is cut short at byte") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(ImportBag, ReceiveTimeWhenTheDriverDoesNotStamp) {
  const Motion<Rx90> m(500, 6);
  std::vector<Msg> msgs = m.messages();
  for (Msg& msg : msgs) msg.stamp_ns = 0;
  const std::string out = bag_path("unstamped.mcap");
  write_bag(msgs, "\"out\":\"" + out + "\"", "\"compression\":\"none\",\"chunked\":true");
  try {
    io::import_bag(out, {}, target_of<Rx90>());
    FAIL() << "no error";
  } catch (const symoro::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("--stamp receive"), std::string::npos) << e.what();
  }
  io::BagSettings s;
  s.stamp = io::StampSource::receive;
  const io::ImportedLog got = io::import_bag(out, s, target_of<Rx90>());
  ASSERT_EQ(got.log.samples(), 500);
  EXPECT_EQ(got.log.time(1), static_cast<double>(msgs[1].receive_ns - msgs[0].receive_ns) * 1e-9);
  EXPECT_EQ(got.log.q, m.q);
}

std::string error_of(const std::string& bag, const io::BagSettings& s, const io::ImportTarget& t) {
  try {
    io::import_bag(bag, s, t);
  } catch (const symoro::DataError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ImportBag, ErrorsNameTheBagAndWhatIsWrong) {
  const Motion<Rx90> m(300, 7);
  std::vector<Msg> msgs = m.messages();
  const std::string out = bag_path("errors.mcap");
  write_bag(msgs, "\"out\":\"" + out + "\"", "\"compression\":\"none\",\"chunked\":true");
  io::BagSettings other;
  other.topic = "/arm/joint_states";
  std::string e = error_of(out, other, target_of<Rx90>());
  EXPECT_NE(e.find("no message on topic /arm/joint_states"), std::string::npos) << e;
  EXPECT_NE(e.find("/joint_states (300)"), std::string::npos) << e;
  other.topic = "/rosout_like";
  e = error_of(out, other, target_of<Rx90>());
  EXPECT_NE(e.find("carries std_msgs/msg/String"), std::string::npos) << e;
  io::ImportTarget renamed = target_of<Rx90>();
  renamed.joints[2] = "elbow";
  e = error_of(out, {}, renamed);
  EXPECT_NE(e.find("names joint elbow"), std::string::npos) << e;
  EXPECT_NE(e.find(out), std::string::npos) << e;
  // Two messages of one stamp that disagree.
  msgs.insert(msgs.begin() + 10, msgs[10]);
  msgs[10].position[0] += 1e-6;
  write_bag(msgs, "\"out\":\"" + out + "\"", "\"compression\":\"none\",\"chunked\":true");
  e = error_of(out, {}, target_of<Rx90>());
  EXPECT_NE(e.find("different values at stamp"), std::string::npos) << e;
  // Not an MCAP file.
  std::ofstream(out) << "time,q1\n0,0\n";
  e = error_of(out, {}, target_of<Rx90>());
  EXPECT_NE(e.find("not an MCAP file"), std::string::npos) << e;
}

}  // namespace
