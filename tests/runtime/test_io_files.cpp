// Files the runtime guards: the folder lock (two studies never write one folder at once) and
// content digests (a log edited in place is a new log; a parameters file edited after identify
// wrote it is known to be edited).
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/digest.hpp"
#include "symoro/io/folder_lock.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::io {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const auto d =
      std::filesystem::temp_directory_path() / ("symoro_io_files_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

TEST(FolderLock, ASecondHolderIsRefusedWithTheFirstsPid) {
  const auto dir = scratch("lock");
  {
    FolderLock first(dir / "study", "dynid identify");
    try {
      FolderLock second(dir / "study", "dynid identify");
      FAIL() << "two holders of one folder";
    } catch (const DataError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("in use by pid " + std::to_string(::getpid()) + " (dynid identify)"), std::string::npos)
          << what;
      EXPECT_NE(what.find((dir / "study").string()), std::string::npos) << what;
    }
    // Another process is refused too (flock excludes open files, not only processes).
    const pid_t child = ::fork();
    if (child == 0) {
      try {
        FolderLock other(dir / "study", "child");
        ::_exit(0);
      } catch (const DataError&) {
        ::_exit(3);
      }
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 3);
  }
  // Released with its holder: the folder can be taken again.
  EXPECT_NO_THROW(FolderLock again(dir / "study", "dynid identify"));
  std::filesystem::remove_all(dir);
}

// /dev/zero grew a reader to 23 GB before it was killed; a FIFO with no writer blocked it for
// ever; /dev/urandom read garbage for minutes. Every reader refuses what is not a regular file,
// at once, whatever name leads to it (a log, its sidecar, dataset.yaml, a YAML file).
TEST(Readers, RefuseDevicesAndFifosAtOnce) {
  const auto dir = std::filesystem::temp_directory_path() / ("symoro_devices_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::filesystem::path target :
       {std::filesystem::path("/dev/zero"), std::filesystem::path("/dev/urandom"), fifo}) {
    SCOPED_TRACE(target.string());
    const auto log = dir / "run.csv", sidecar = dir / "run.meta.yaml", manifest = dir / "dataset.yaml";
    for (const auto& link : {log, sidecar, manifest}) {
      std::filesystem::remove(link);
      std::filesystem::create_symlink(target, link);
    }
    const auto refused = [&](const std::function<void()>& read, const std::filesystem::path& named) {
      try {
        read();
        ADD_FAILURE() << "read " << named;
      } catch (const symoro::DataError& e) {
        EXPECT_EQ(e.file(), named.string()) << e.what();
        EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
      }
    };
    refused([&] { symoro::io::read_log(log); }, log);
    refused([&] { symoro::io::read_log_metadata(log); }, sidecar);
    refused([&] { symoro::io::read_dataset(dir); }, manifest);
    refused([&] { symoro::io::load_yaml_file(sidecar); }, sidecar);
  }
  std::filesystem::remove_all(dir);
}

// A 100 MB scalar was echoed whole in the error (100-200 MB of output): a message keeps its head
// and tail and says how much it left out (issue 42, item 17).
TEST(Readers, AHugeValueIsNotEchoedWhole) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("symoro_huge_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string key(10 << 20, 'k');
  std::ofstream(dir / "dataset.yaml") << "robot: arm\n? " << key
                                      << "\n: 1\n";  // an explicit key: no 1024-character bound
  try {
    symoro::io::read_dataset(dir);
    ADD_FAILURE() << "a 10 MB unknown key accepted";
  } catch (const symoro::DataError& e) {
    const std::string what = e.what();
    EXPECT_LT(what.size(), 3000u);
    EXPECT_NE(what.find("characters left out"), std::string::npos) << what.substr(0, 300);
    EXPECT_NE(what.find((dir / "dataset.yaml").string()), std::string::npos) << what.substr(0, 300);
  }
  std::filesystem::remove_all(dir);
  const symoro::DataError short_one("f.yaml", 3, "short");
  EXPECT_STREQ(short_one.what(), "f.yaml:3: error: short");
}

// --params given a CSV said "operator[] call on a scalar" (issue 42, item 17).
TEST(Readers, AParametersFileThatIsNoMapIsNamed) {
  const std::filesystem::path csv =
      std::filesystem::temp_directory_path() / ("symoro_params_" + std::to_string(::getpid()) + ".csv");
  std::ofstream(csv) << "name,value\nXX1,0.1\nXY1,0.2\n";
  for (const std::function<void()>& read :
       std::vector<std::function<void()>>{[&] {
                                            read_parameters_yaml(csv.string(), {"XX1", "XY1"});
                                          },
                                          [&] { parameters_accepted(csv.string()); },
                                          [&] {
                                            parameters_integrity(csv.string(), {"XX1", "XY1"});
                                          }}) {
    try {
      read();
      ADD_FAILURE() << "a CSV read as parameters";
    } catch (const DataError& e) {
      EXPECT_EQ(std::string(e.what()),
                csv.string() +
                    ":1: error: not a parameters file: a YAML map with a 'parameters:' list (a study's "
                    "report/parameters.yaml) was expected; a .csv is not read here");
    }
  }
  std::filesystem::remove(csv);
}

TEST(Digest, FileDigestIsTheBytesDigestAndSeesOneChangedByte) {
  const auto dir = scratch("digest");
  std::mt19937 rng(7);
  std::string bytes(3 * (1 << 20) + 17, '\0');  // more than one read block
  for (char& c : bytes) c = static_cast<char>(rng());
  std::ofstream(dir / "a.bin", std::ios::binary) << bytes;
  const std::string d = file_digest(dir / "a.bin");
  EXPECT_EQ(d, digest_of(bytes));
  EXPECT_EQ(d.size(), 32u);
  bytes[2 * (1 << 20) + 5] ^= 1;  // same size, one bit
  std::ofstream(dir / "a.bin", std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_NE(file_digest(dir / "a.bin"), d);
  EXPECT_THROW(file_digest(dir / "missing.bin"), DataError);
  std::filesystem::remove_all(dir);
}

// A parameters file as identify writes it is intact; one value or the accepted flag edited, or
// the digest removed, is not, and says why.
TEST(ParametersDigest, AnEditedValueOrFlagBreaksIt) {
  const auto dir = scratch("params");
  const std::vector<std::string> names = {"ZZR1", "MX2"};
  const Eigen::Vector2d phi(0.0121, 0.0437);
  const auto write = [&](const std::string& file, bool accepted, double mx2, bool with_digest) {
    std::ofstream f(dir / file);
    f << "robot: \"crane_x7\"\nmodel: \"reduced\"\naccepted: " << (accepted ? "true" : "false") << "\n";
    if (with_digest) f << "digest: " << parameters_digest("crane_x7", "reduced", true, names, phi) << "\n";
    f << "parameters:\n  - {name: \"ZZR1\", unit: \"kg m^2\", value: 0.0121}\n  - {name: \"MX2\", unit: \"kg m\", "
         "value: "
      << mx2 << "}\n";
  };
  write("ok.yaml", true, 0.0437, true);
  EXPECT_TRUE(parameters_integrity((dir / "ok.yaml").string(), names).intact);
  write("value.yaml", true, 50, true);
  const ParametersIntegrity v = parameters_integrity((dir / "value.yaml").string(), names);
  EXPECT_FALSE(v.intact);
  EXPECT_NE(v.why.find("does not match its digest"), std::string::npos) << v.why;
  write("flag.yaml", false, 0.0437, true);
  EXPECT_FALSE(parameters_integrity((dir / "flag.yaml").string(), names).intact);
  write("none.yaml", true, 0.0437, false);
  const ParametersIntegrity n = parameters_integrity((dir / "none.yaml").string(), names);
  EXPECT_FALSE(n.intact);
  EXPECT_NE(n.why.find("no 'digest:'"), std::string::npos) << n.why;
  std::filesystem::remove_all(dir);
}

// The timing the parameters were identified with: read in seconds; absent in files from before the
// key; anything but a number of ms within +-1000 refused with its line.
TEST(ParametersTiming, TheTorqueDelayReadsBackAndABadOneIsNamed) {
  const auto dir = scratch("timing");
  const auto write = [&](const std::string& file, const std::string& line) {
    std::ofstream(dir / file) << "robot: \"ur5\"\nmodel: \"full\"\n"
                              << line << "parameters:\n  - {name: \"ZZR1\", value: 0.0121}\n";
    return (dir / file).string();
  };
  EXPECT_EQ(parameters_torque_delay(write("ms.yaml", "torque_delay_ms: -2.5\n")), -0.0025);
  EXPECT_FALSE(parameters_torque_delay(write("old.yaml", "")).has_value());
  for (const std::string& bad : {"torque_delay_ms: soon\n", "torque_delay_ms: 1e9\n", "torque_delay_ms: .nan\n"}) {
    const std::string file = write("bad.yaml", bad);
    try {
      parameters_torque_delay(file);
      ADD_FAILURE() << bad;
    } catch (const DataError& e) {
      EXPECT_EQ(std::string(e.what()), file + ":3: error: torque_delay_ms: expected a number of ms from -1000 to 1000");
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace symoro::io
