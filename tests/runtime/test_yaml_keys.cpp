// Every YAML file the runtime reads refuses a key it does not know, at the key's line, with the
// nearest known key: a typo was ignored before (with `windw:` for `window:` in dataset.yaml, the
// fitting run covered the held-out part too). A syntax error names its line and column, and so
// does a quoted value without its closing quote, which yaml-cpp reads as text to the end of the
// file. Files of robots/ are read from copies with one line edited.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <symoro/crane_x7.hpp>
#include <unistd.h>

#include "symoro/control/description.hpp"
#include "symoro/error.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/config.hpp"

namespace fs = std::filesystem;
using symoro::DataError;

namespace {

const fs::path kCrane = fs::path(SYMORO_ROBOTS_DIR) / "crane_x7";

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// `text` with its first `from` replaced by `to`.
std::string edited(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("not in the file: " + from);
  return text.replace(at, from.size(), to);
}

// The 1-based line of the first `marker` in `text`.
int line_of(const std::string& text, const std::string& marker) {
  const auto at = text.find(marker);
  if (at == std::string::npos) throw std::logic_error("no marker " + marker);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

std::vector<symoro::JointInfo> crane_joints() {
  return {symoro::crane_x7::Model::joints.begin(), symoro::crane_x7::Model::joints.end()};
}

// A two-joint arm (the shape of robots/planar2r) for the readers that take the robot's joints.
std::vector<symoro::JointInfo> arm2_joints() {
  return {{"shoulder", symoro::JointType::Revolute, -3.1, 3.1, 3, 40, -3.1, 3.1},
          {"elbow", symoro::JointType::Revolute, -2.6, 2.6, 3, 20, -2.6, 2.6}};
}

class YamlKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("symoro_yaml_keys_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // `read_file` must refuse `file` at `line` ("file:line: error: unknown key '<key>' ... did you
  // mean '<near>'? (known keys: ...)").
  template <class F>
  static void expect_unknown(F read_file, const fs::path& file, int line, const std::string& key,
                             const std::string& near) {
    try {
      read_file();
      ADD_FAILURE() << "accepted the key '" << key << "' in " << file;
    } catch (const DataError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), file.string()) << what;
      EXPECT_EQ(e.line(), line) << what;
      EXPECT_EQ(what.rfind(file.string() + ":" + std::to_string(line) + ": error: unknown key '" + key + "' in ", 0),
                0u)
          << what;
      EXPECT_NE(what.find("; did you mean '" + near + "'? (known keys: "), std::string::npos) << what;
    }
  }

  // `read_file` must refuse `file` with a YAML syntax error at `line` (and some column).
  template <class F>
  static void expect_syntax_error(F read_file, const fs::path& file, int line, const std::string& message) {
    try {
      read_file();
      ADD_FAILURE() << "accepted broken YAML in " << file;
    } catch (const DataError& e) {
      const std::string what = e.what(), at = file.string() + ":" + std::to_string(line) + ":";
      EXPECT_EQ(e.line(), line) << what;
      EXPECT_EQ(what.rfind(at, 0), 0u) << what;
      EXPECT_NE(what.find(": error: YAML syntax error: "), std::string::npos) << what;
      EXPECT_NE(what.find(message), std::string::npos) << what;
    }
  }

  fs::path dir_;
};

TEST(NearestName, MisspellingsFindTheirKeyAndStrangersNone) {
  const std::vector<std::string> run{"trajectory", "family", "trial", "file", "window"};
  EXPECT_EQ(symoro::io::nearest_name("windw", run), "window");
  EXPECT_EQ(symoro::io::nearest_name("trail", run), "trial");  // two letters swapped
  EXPECT_EQ(symoro::io::nearest_name("Family", run), "family");
  EXPECT_EQ(symoro::io::nearest_name("colour", run), "");
  EXPECT_EQ(symoro::io::nearest_name("splti", {"split", "source", "runs"}), "split");
  EXPECT_EQ(symoro::io::nearest_name("x", {"q", "tau"}), "");
  EXPECT_EQ(symoro::io::nearest_name("YM", {"M", "MX", "MY"}), "MY");  // of two at one edit, the one as long
}

// ---- dataset.yaml ------------------------------------------------------------------------------

TEST_F(YamlKeys, DatasetRefusesTyposOfWindowSplitAndTrial) {
  fs::create_directories(dir_ / "data");
  write(dir_ / "data" / "a.csv", "");  // read_dataset checks that the run's file exists
  const std::string good =
      "format: symoro-dataset 1\n"
      "robot: \"arm6\"\n"
      "source: imported\n"
      "split: 0.7\n"
      "runs:\n"
      "  - {trajectory: a, family: F, trial: 1, file: a.csv, window: [0, 7]}\n"
      "  - trajectory: a_heldout\n"
      "    family: V\n"
      "    trial: 1\n"
      "    file: a.csv\n"
      "    window: [7, .inf]\n";
  const fs::path manifest = dir_ / "data" / "dataset.yaml";
  write(manifest, good);
  const symoro::io::Dataset d = symoro::io::read_dataset(dir_ / "data");
  ASSERT_EQ(d.runs.size(), 2u);
  EXPECT_EQ(d.runs[0].window_end, 7);
  EXPECT_EQ(d.runs[1].window_start, 7);
  const auto read_it = [&] { symoro::io::read_dataset(dir_ / "data"); };

  write(manifest, edited(good, "a.csv, window:", "a.csv, windw:"));
  expect_unknown(read_it, manifest, 6, "windw", "window");
  write(manifest, edited(good, "    window: [7", "    windw: [7"));
  expect_unknown(read_it, manifest, 11, "windw", "window");
  write(manifest, edited(good, "split:", "splti:"));
  expect_unknown(read_it, manifest, 4, "splti", "split");
  write(manifest, edited(good, "    trial: 1", "    trail: 1"));
  expect_unknown(read_it, manifest, 9, "trail", "trial");
  // A quote left open swallows the rest of the file.
  write(manifest, edited(good, "robot: \"arm6\"", "robot: \"arm6"));
  expect_syntax_error(read_it, manifest, 2, "the quoted value opened here by \" has no closing quote");
}

// ---- import mappings ---------------------------------------------------------------------------

TEST_F(YamlKeys, ImportMappingRefusesTyposAndUnclosedQuotes) {
  const fs::path m = dir_ / "map.yaml";
  const std::string good = "time: t\nq: \"pos_*\"\ntau: [e1, e2]\nunits: {time: ms, angle: deg}\nheader: yes\n";
  write(m, good);
  EXPECT_EQ(symoro::io::read_import_mapping(m).tau, "e1,e2");
  const auto read_it = [&] { symoro::io::read_import_mapping(m); };
  write(m, edited(good, "tau:", "tua:"));
  expect_unknown(read_it, m, 3, "tua", "tau");
  write(m, edited(good, "angle:", "angel:"));
  expect_unknown(read_it, m, 4, "angel", "angle");
  write(m, edited(good, "header:", "heade:"));
  expect_unknown(read_it, m, 5, "heade", "header");
  // Before: q and tau vanished into the quoted text, and dynid import asked which columns hold
  // time, q and tau.
  write(m, edited(good, "q: \"pos_*\"", "q: \"pos_*"));
  expect_syntax_error(read_it, m, 2, "the quoted value opened here by \" has no closing quote");
  try {
    read_it();
  } catch (const DataError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(m.string() + ":2:4: error: ", 0), 0u) << e.what();
  }
  write(m, edited(good, "time: t", "time: 't"));
  expect_syntax_error(read_it, m, 1, "the quoted value opened here by ' has no closing quote");
  write(m, edited(good, "[e1, e2]", "[e1, e2"));
  expect_syntax_error(read_it, m, 4, "end of sequence flow not found");
}

// ---- controller.yaml ---------------------------------------------------------------------------

TEST_F(YamlKeys, ControllerDescriptionRefusesTyposOnTwoRobots) {
  const fs::path c = dir_ / "controller.yaml";
  const std::string crane = read(kCrane / "controller.yaml");
  const auto read8 = [&] { symoro::control::read_controller_description(c, 8); };
  write(c, crane);
  EXPECT_NO_THROW(read8());
  write(c, edited(crane, "bandwidth:", "bandwith:"));
  expect_unknown(read8, c, line_of(crane, "bandwidth:"), "bandwith", "bandwidth");
  write(c, edited(crane, "  damping:", "  dampin:"));
  expect_unknown(read8, c, line_of(crane, "  damping:"), "dampin", "damping");

  const std::string arm2 =
      "format: symoro-controller 1\n"
      "period: 0.001\n"
      "pseudo_derivative_time: 0.002\n"
      "communication_delay: 0.0005\n"
      "realization: {inertia: [0.2, 0.05], damping: [0.1, 0.05]}\n"
      "bandwidth: [20, 20]\n"
      "damping_ratio: [1, 1]\n";
  const auto read2 = [&] { symoro::control::read_controller_description(c, 2); };
  write(c, arm2);
  EXPECT_NO_THROW(read2());
  write(c, edited(arm2, "damping_ratio:", "damping_ration:"));
  expect_unknown(read2, c, 7, "damping_ration", "damping_ratio");
  write(c, edited(arm2, "period: 0.001", "period: \"0.001"));
  expect_syntax_error(read2, c, 2, "has no closing quote");
}

// ---- hardware.yaml -----------------------------------------------------------------------------

TEST_F(YamlKeys, HardwareConfigRefusesTyposOnTwoRobots) {
  const fs::path h = dir_ / "hardware.yaml";
  const std::string crane = read(kCrane / "hardware.yaml");
  const auto read_crane = [&] { symoro::hardware::read_hardware_config(h, crane_joints()); };
  write(h, crane);
  EXPECT_NO_THROW(read_crane());
  write(h, edited(crane, "return_delay_time: 0", "return_delay_tme: 0"));
  expect_unknown(read_crane, h, line_of(crane, "return_delay_time: 0"), "return_delay_tme", "return_delay_time");
  write(h, edited(crane, "{name: elbow,           id: 5, model: XM430-W350, zero: 2048, direction: 1, current_limit",
                  "{name: elbow,           id: 5, model: XM430-W350, zero: 2048, directon: 1, current_limit"));
  expect_unknown(read_crane, h, line_of(crane, "{name: elbow, "), "directon", "direction");

  const std::string arm2 =
      "format: symoro-hardware 1\n"
      "bus: {baud: 1000000}\n"
      "models:\n"
      "  XM430-W350: {model_number: 1020, torque_constant: 2.3179, current_unit: 0.00269, current_limit: 3.209}\n"
      "joints:\n"
      "  - {name: shoulder, id: 1, model: XM430-W350, current_limit: 2}\n"
      "  - {name: elbow, id: 2, model: XM430-W350, current_limit: 2}\n"
      "safety:\n"
      "  watchdog_cycles: 3\n";
  const auto read2 = [&] { symoro::hardware::read_hardware_config(h, arm2_joints()); };
  write(h, arm2);
  EXPECT_NO_THROW(read2());
  write(h, edited(arm2, "watchdog_cycles", "watchdog_cylces"));
  expect_unknown(read2, h, 9, "watchdog_cylces", "watchdog_cycles");
  write(h, edited(arm2, "torque_constant", "torque_konstant"));
  expect_unknown(read2, h, 4, "torque_konstant", "torque_constant");
}

// ---- anchors, aliases and documents ------------------------------------------------------------

// A self-merging alias crashed every reader (a stack overflow); ten levels of ten aliases ran
// for minutes; a second document was ignored. Refused in every reader at its line, before any
// node is built (anchors alone stay allowed: twin.yaml uses them).
TEST_F(YamlKeys, AnchorsAliasesAndASecondDocumentAreRefusedByEveryReader) {
  std::string laughs = "lol: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int k = 1; k < 10; ++k) {
    laughs += fmt::format("l{}: &l{} [", k, k);
    for (int i = 0; i < 10; ++i) laughs += fmt::format("{}*l{}", i ? ", " : "", k - 1);
    laughs += "]\n";
  }
  struct Poison {
    const char* name;
    std::string text;  // appended to a valid file
    std::string message;
  };
  const std::vector<Poison> poisons = {
      {"self-merge", "zz: &s {<<: *s}\n", "a cycle no reader can follow"},
      {"billion laughs", laughs, "YAML aliases expand this document past 1000000 nodes"},
      {"alias", "zz: *nothing\n", "the referenced anchor is not defined"},
      {"second document", "---\nformat: other\n", "a second YAML document"}};
  fs::create_directories(dir_ / "data");
  write(dir_ / "data" / "a.csv", "");
  const std::string dataset =
      "format: symoro-dataset 1\nrobot: arm6\nruns:\n  - {trajectory: a, family: F, trial: 1, file: a.csv}\n";
  struct Reader {
    const char* name;
    fs::path file;
    std::string valid;
    std::function<void()> read;
  };
  const fs::path h = dir_ / "hardware.yaml", c = dir_ / "controller.yaml";
  const std::vector<Reader> readers = {
      {"hardware.yaml", h, read(kCrane / "hardware.yaml"),
       [&] { symoro::hardware::read_hardware_config(h, crane_joints()); }},
      {"controller.yaml", c, read(kCrane / "controller.yaml"),
       [&] { symoro::control::read_controller_description(c, 8); }},
      {"dataset.yaml", dir_ / "data" / "dataset.yaml", dataset, [&] { symoro::io::read_dataset(dir_ / "data"); }},
      {"YAML text", dir_ / "text.yaml", "format: x\n", [&] { symoro::io::load_yaml_file(dir_ / "text.yaml"); }},
  };
  for (const Reader& r : readers) {
    for (const Poison& p : poisons) {
      SCOPED_TRACE(std::string(r.name) + ", " + p.name);
      const std::string text = r.valid + p.text;
      write(r.file, text);
      // At the poison's line (the laughs: the line whose alias passes the bound).
      const int first = 1 + static_cast<int>(std::count(r.valid.begin(), r.valid.end(), '\n'));
      const int last = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
      try {
        r.read();
        ADD_FAILURE() << "accepted";
      } catch (const DataError& e) {
        EXPECT_GE(e.line(), first) << e.what();
        EXPECT_LE(e.line(), std::string(p.name) == "billion laughs" ? last : first) << e.what();
        EXPECT_NE(std::string(e.what()).find(p.message), std::string::npos) << e.what();
      }
    }
  }
}

// A UTF-8 byte order mark (a Windows editor's) before a dataset.yaml with quoted values was
// reported as an open quote on line 10: it is no content, and the file reads as without it; an
// error after it keeps its line.
TEST_F(YamlKeys, AByteOrderMarkIsNoContent) {
  fs::create_directories(dir_ / "data");
  write(dir_ / "data" / "a.csv", "");
  const std::string dataset =
      "format: \"symoro-dataset 1\"\nrobot: 'arm6'\nruns:\n  - {trajectory: \"a\", family: F, trial: 1, file: "
      "'a.csv'}\n";
  write(dir_ / "data" / "dataset.yaml", "\xEF\xBB\xBF" + dataset);
  const symoro::io::Dataset d = symoro::io::read_dataset(dir_ / "data");
  EXPECT_EQ(d.robot, "arm6");
  ASSERT_EQ(d.runs.size(), 1u);
  EXPECT_EQ(d.runs[0].trajectory, "a");
  write(dir_ / "data" / "dataset.yaml", "\xEF\xBB\xBF" + dataset + "windw: 1\n");
  try {
    symoro::io::read_dataset(dir_ / "data");
    ADD_FAILURE() << "a typo accepted";
  } catch (const DataError& e) {
    EXPECT_EQ(e.line(), 5) << e.what();
    EXPECT_EQ(std::string(e.what()).find("quote"), std::string::npos) << e.what();
  }
}

// ---- twin.yaml and its override file -----------------------------------------------------------

TEST_F(YamlKeys, TwinConfigAndOverridesRefuseTypos) {
  fs::copy_file(kCrane / "controller.yaml", dir_ / "controller.yaml");  // twin.yaml has no controller section
  const fs::path t = dir_ / "twin.yaml", o = dir_ / "overrides.yaml";
  const std::string crane = read(kCrane / "twin.yaml");
  write(t, crane);
  EXPECT_NO_THROW(symoro::twin::read_twin_config(t, 8));
  const auto read_twin = [&] { symoro::twin::read_twin_config(t, 8); };
  write(t, edited(crane, "  max_step:", "  max_stpe:"));
  expect_unknown(read_twin, t, line_of(crane, "  max_step:"), "max_stpe", "max_step");
  write(t, edited(crane, "smoothing_velocity:", "smoothing_velocty:"));
  expect_unknown(read_twin, t, line_of(crane, "smoothing_velocity:"), "smoothing_velocty", "smoothing_velocity");

  write(t, crane);
  const auto read_override = [&] { symoro::twin::read_twin_config(t, 8, o); };
  write(o, "effects:\n  coulomb: {enabled: false}\n  payload: {enabeld: true}\n");
  expect_unknown(read_override, o, 3, "enabeld", "enabled");
  write(o, "effects:\n  colomb: {enabled: false}\n");
  expect_unknown(read_override, o, 2, "colomb", "coulomb");
  write(o, "effects:\n  coulomb:\n    enabled: 'false\n");
  expect_syntax_error(read_override, o, 3, "has no closing quote");
  // A file that is a scalar or a list: yaml-cpp's BadSubscript escaped every handler (fuzz_yaml).
  for (const char* text : {"just text\n", "- a\n- b\n"}) {
    write(t, text);
    try {
      read_twin();
      ADD_FAILURE() << "accepted: " << text;
    } catch (const DataError& e) {
      EXPECT_EQ(e.line(), 1) << e.what();
      EXPECT_NE(std::string(e.what()).find("expected a YAML map of sections"), std::string::npos) << e.what();
    }
    write(o, text);
    write(t, crane);
    EXPECT_THROW(read_override(), DataError) << text;
  }
}

// ---- trajectories.yaml -------------------------------------------------------------------------

TEST_F(YamlKeys, TrajectoryDesignRefusesTypos) {
  const fs::path d = dir_ / "trajectories.yaml";
  const std::string crane = read(kCrane / "trajectories.yaml");
  const auto read_it = [&] { symoro::trajectory::TrajectoryDesign::read(d, crane_joints()); };
  write(d, crane);
  EXPECT_NO_THROW(read_it());
  write(d, edited(crane, "wrist_variant:", "wrist_varaint:"));
  expect_unknown(read_it, d, line_of(crane, "wrist_variant:"), "wrist_varaint", "wrist_variant");
}

}  // namespace
