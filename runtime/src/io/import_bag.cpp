// ROS 2 bags (MCAP) into the project's log: JointState messages gathered into rows by stamp and
// matched to the robot's joints by name (symoro/io/import_bag.hpp).
#include "symoro/io/import_bag.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/mcap.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/ros2_joint_state.hpp"

namespace symoro::io {

namespace fs = std::filesystem;

namespace {

constexpr double kAbsent = std::numeric_limits<double>::quiet_NaN();

// One JointState message on the topic, its values put in the robot's joint order (NaN: not in it).
struct Entry {
  std::int64_t stamp = 0;    // ns
  std::uint64_t number = 0;  // 1-based, among the topic's messages
  std::vector<double> q, qd, tau;
};

int yaml_line(const YAML::Node& n) { return n.Mark().line + 1; }

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// The topic's messages of every file of the bag, decoded.
struct Gathered {
  std::vector<Entry> entries;
  std::map<std::string, std::uint64_t> other_topics;  // topic -> messages
  std::set<std::string> ignored_names;                // names the robot does not have
  std::vector<std::string> cut;                       // remarks on files cut short
  bool any_header_stamp = false;
};

class Gatherer {
 public:
  Gatherer(const fs::path& bag, const BagSettings& s, const ImportTarget& t) : bag_(bag), settings_(s), target_(t) {}

  void file(const fs::path& f) {
    const mcap::ReadSummary r = mcap::read_mcap(
        f, [&](const mcap::Message& m, const mcap::Channel& c, const mcap::Schema* s) { message(f, m, c, s); });
    if (r.cut_short)
      out.cut.push_back(
          fmt::format("{} is cut short at byte {} of {} (no footer): the {} messages before the cut "
                      "were read",
                      f.filename().string(), r.cut_at, r.bytes, r.messages));
  }

  Gathered out;

 private:
  void message(const fs::path& f, const mcap::Message& m, const mcap::Channel& c, const mcap::Schema* s) {
    if (c.topic != settings_.topic) {
      ++out.other_topics[c.topic];
      return;
    }
    const std::uint64_t number = out.entries.size() + 1;
    const auto where = [&] { return fmt::format("{}: message {} on {}", f.string(), number, c.topic); };
    if (!checked_.count(c.id)) {
      if (!s || s->name != ros2::kJointStateType)
        throw DataError(bag_.string(), 0,
                        fmt::format("topic {} carries {}, not {} (name the JointState topic with --topic)", c.topic,
                                    s ? s->name : std::string("messages without a schema"), ros2::kJointStateType));
      if (c.message_encoding != "cdr")
        throw DataError(
            bag_.string(), 0,
            fmt::format("topic {} is encoded as '{}'; this reader decodes ROS 2's cdr", c.topic, c.message_encoding));
      if (s->encoding == "ros2msg") try {
          ros2::check_joint_state_definition(s->data);
        } catch (const std::invalid_argument& e) {
          throw DataError(bag_.string(), 0, fmt::format("topic {}'s {}: {}", c.topic, s->name, e.what()));
        }
      checked_.insert(c.id);
    }
    ros2::JointState js;
    try {
      js = ros2::decode_joint_state(m.data, m.size);
    } catch (const std::invalid_argument& e) {
      throw DataError(bag_.string(), 0, fmt::format("{} does not decode as JointState: {}", where(), e.what()));
    }
    Entry e;
    e.number = number;
    if (settings_.stamp == StampSource::header) {
      e.stamp = std::int64_t{js.sec} * 1000000000 + js.nanosec;
      out.any_header_stamp = out.any_header_stamp || e.stamp != 0;
    } else {
      if (m.log_time > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
        throw DataError(bag_.string(), 0, fmt::format("{}: receive time {} ns is out of range", where(), m.log_time));
      e.stamp = static_cast<std::int64_t>(m.log_time);
    }
    const std::size_t n = target_.joints.size();
    e.q.assign(n, kAbsent);
    e.qd.assign(n, kAbsent);
    e.tau.assign(n, kAbsent);
    for (std::size_t i = 0; i < js.name.size(); ++i) {
      const auto j = std::find(target_.joints.begin(), target_.joints.end(), js.name[i]);
      if (j == target_.joints.end()) {
        out.ignored_names.insert(js.name[i]);
        continue;
      }
      const auto k = static_cast<std::size_t>(j - target_.joints.begin());
      if (!std::isnan(e.q[k]))
        throw DataError(bag_.string(), 0, fmt::format("{} names joint {} twice", where(), js.name[i]));
      if (!js.position.empty()) e.q[k] = js.position[i];
      if (!js.velocity.empty()) e.qd[k] = js.velocity[i];
      if (!js.effort.empty()) e.tau[k] = js.effort[i];
      // NaN is what drivers publish for a value they do not have: absent, as an empty array is.
      for (double v : {e.q[k], e.qd[k], e.tau[k]})
        if (std::isinf(v))
          throw DataError(bag_.string(), 0, fmt::format("{}: joint {} has an infinite value", where(), js.name[i]));
    }
    out.entries.push_back(std::move(e));
  }

  const fs::path& bag_;
  const BagSettings& settings_;
  const ImportTarget& target_;
  std::set<std::uint16_t> checked_;
};

// Merges `from` into `into` (one stamp's messages); false when a joint's value differs.
bool merge(std::vector<double>& into, const std::vector<double>& from, std::size_t& conflict) {
  for (std::size_t j = 0; j < into.size(); ++j) {
    if (std::isnan(from[j])) continue;
    if (!std::isnan(into[j]) && into[j] != from[j]) {
      conflict = j;
      return false;
    }
    into[j] = from[j];
  }
  return true;
}

bool whole(const std::vector<double>& v) {
  return std::none_of(v.begin(), v.end(), [](double x) { return std::isnan(x); });
}

std::string stamp_text(std::int64_t ns) {
  const std::int64_t s = ns >= 0 ? ns / 1000000000 : -((-ns + 999999999) / 1000000000);
  return fmt::format("{}.{:09d} s", s, ns - s * 1000000000);
}

}  // namespace

bool is_bag(const fs::path& input) {
  std::error_code ec;
  return fs::is_directory(input, ec) || input.extension() == ".mcap";
}

std::vector<fs::path> bag_files(const fs::path& input) {
  std::error_code ec;
  if (!fs::is_directory(input, ec)) return {input};
  const fs::path meta = input / "metadata.yaml";
  if (!fs::exists(meta))
    throw DataError(input.string(), 0,
                    "a folder without metadata.yaml is no ROS 2 bag (give the .mcap file itself, or the bag folder "
                    "`ros2 bag record` wrote)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(meta.string());
  } catch (const YAML::Exception& e) {
    throw DataError(meta.string(), e.mark.line + 1, e.msg);
  }
  const YAML::Node info = root["rosbag2_bagfile_information"];
  if (!info || !info.IsMap())
    throw DataError(meta.string(), 1, "no rosbag2_bagfile_information: not a ROS 2 bag's metadata");
  const YAML::Node storage = info["storage_identifier"];
  const std::string id = storage && storage.IsScalar() ? storage.Scalar() : "";
  if (id != "mcap")
    throw DataError(meta.string(), storage ? yaml_line(storage) : yaml_line(info),
                    fmt::format("storage '{}': this reader takes MCAP bags (convert with `ros2 bag convert` to "
                                "storage_id mcap)",
                                id));
  if (const YAML::Node c = info["compression_format"]; c && c.IsScalar() && !c.Scalar().empty())
    throw DataError(meta.string(), yaml_line(c),
                    fmt::format("the bag's files are compressed whole ({}); MCAP's own chunk compression is read, "
                                "whole-file compression is not (record with --storage-preset-profile, or "
                                "decompress the files)",
                                c.Scalar()));
  const YAML::Node paths = info["relative_file_paths"];
  if (!paths || !paths.IsSequence() || paths.size() == 0)
    throw DataError(meta.string(), yaml_line(paths ? paths : info), "relative_file_paths lists no file");
  std::vector<fs::path> files;
  for (const YAML::Node& p : paths) {
    if (!p.IsScalar()) throw DataError(meta.string(), yaml_line(p), "a relative file path must be a string");
    const fs::path f = input / p.Scalar();
    if (!fs::is_regular_file(f, ec))
      throw DataError(meta.string(), yaml_line(p), fmt::format("{} is listed but not there", f.string()));
    files.push_back(f);
  }
  return files;
}

std::vector<double> robot_torque_constants(const fs::path& robot_yaml) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(robot_yaml.string());
  } catch (const YAML::Exception& e) {
    throw DataError(robot_yaml.string(), e.mark.line + 1, e.msg);
  }
  std::vector<double> k;
  const YAML::Node joints = root["joints"];
  if (!joints || !joints.IsSequence()) return k;
  bool any = false, all = true;
  for (const YAML::Node& j : joints) {
    const YAML::Node c = j.IsMap() ? j["torque_constant"] : YAML::Node();
    if (!c) {
      all = false;
      continue;
    }
    any = true;
    double v = 0;
    if (!c.IsScalar() || !YAML::convert<double>::decode(c, v) || !(v > 0 && std::isfinite(v)))
      throw DataError(robot_yaml.string(), yaml_line(c), "torque_constant must be a positive number (N m/A)");
    k.push_back(v);
  }
  if (any && !all)
    throw DataError(robot_yaml.string(), yaml_line(joints),
                    "torque_constant is given for some joints, not all (one per joint, N m/A)");
  return k;
}

namespace {

// The errors a bag's messages can show before any row is made.
void check_gathered(const Gathered& got, const fs::path& input, const BagSettings& settings,
                    const ImportTarget& target) {
  if (got.entries.empty()) {
    std::string topics;
    for (const auto& [t, c] : got.other_topics) topics += fmt::format("{}{} ({})", topics.empty() ? "" : ", ", t, c);
    throw DataError(input.string(), 0,
                    fmt::format("no message on topic {}; the bag has {}", settings.topic,
                                topics.empty() ? std::string("no messages") : topics));
  }
  if (settings.stamp == StampSource::header && !got.any_header_stamp)
    throw DataError(input.string(), 0,
                    fmt::format("every message on {} has header.stamp 0 (the driver does not stamp them): use the "
                                "recorder's receive time (--stamp receive)",
                                settings.topic));
  for (std::size_t j = 0; j < target.joints.size(); ++j)
    if (std::all_of(got.entries.begin(), got.entries.end(), [&](const Entry& e) { return std::isnan(e.q[j]); })) {
      std::vector<std::string> seen(got.ignored_names.begin(), got.ignored_names.end());
      throw DataError(input.string(), 0,
                      fmt::format("no message on {} names joint {} (the robot's joints: {}; names in the bag that "
                                  "the robot has not: {})",
                                  settings.topic, target.joints[j], joined(target.joints),
                                  seen.empty() ? std::string("none") : joined(seen)));
    }
}

// One row per stamp, its messages merged; the partial stamps counted, not kept.
struct Merged {
  std::vector<Entry> rows;
  std::vector<int> partial_by_joint;
  int partial = 0;
  std::vector<int> duplicates;  // message numbers
  int stamps() const { return static_cast<int>(rows.size()) + partial; }
  std::string missing_most(const ImportTarget& target) const {
    std::vector<std::string> names;
    const int worst = *std::max_element(partial_by_joint.begin(), partial_by_joint.end());
    for (std::size_t j = 0; j < partial_by_joint.size(); ++j)
      if (partial_by_joint[j] == worst) names.push_back(target.joints[j]);
    return fmt::format("{} (missing at {} stamps)", joined(names), worst);
  }
};

Merged merge_stamps(Gathered& got, const fs::path& input, const BagSettings& settings, const ImportTarget& target) {
  const std::size_t n = target.joints.size();
  std::stable_sort(got.entries.begin(), got.entries.end(),
                   [](const Entry& a, const Entry& b) { return a.stamp < b.stamp; });
  Merged m;
  m.partial_by_joint.assign(n, 0);
  for (std::size_t i = 0; i < got.entries.size();) {
    Entry row = got.entries[i];
    std::size_t k = i + 1;
    for (; k < got.entries.size() && got.entries[k].stamp == row.stamp; ++k) {
      const Entry& e = got.entries[k];
      std::size_t j = 0;
      const auto before = row.q;
      if (!merge(row.q, e.q, j) || !merge(row.qd, e.qd, j) || !merge(row.tau, e.tau, j))
        throw DataError(input.string(), 0,
                        fmt::format("messages {} and {} on {} give joint {} different values at stamp {}", row.number,
                                    e.number, settings.topic, target.joints[j], stamp_text(row.stamp)));
      bool adds = false;
      for (std::size_t c = 0; c < n; ++c) adds = adds || (std::isnan(before[c]) && !std::isnan(e.q[c]));
      if (!adds) m.duplicates.push_back(static_cast<int>(e.number));
    }
    i = k;
    if (whole(row.q) && whole(row.tau)) {
      m.rows.push_back(std::move(row));
    } else {
      ++m.partial;
      for (std::size_t j = 0; j < n; ++j) m.partial_by_joint[j] += std::isnan(row.q[j]) || std::isnan(row.tau[j]);
    }
  }
  if (m.rows.size() < 4 || 2 * m.partial > m.stamps())
    throw DataError(input.string(), 0,
                    fmt::format("only {} of the {} stamps on {} give every joint's position and effort; the joints "
                                "missing most: {}. Are they published with other stamps (another driver), or "
                                "without effort?",
                                m.rows.size(), m.stamps(), settings.topic, m.missing_most(target)));
  return m;
}

// The log's samples from the rows (time from the first, effort as torque); returns whether the
// velocity was measured in every row (else it is differentiated from q).
bool fill_samples(const Merged& m, const fs::path& input, const BagSettings& settings, ImportedLog& out) {
  const std::vector<Entry>& rows = m.rows;
  const auto R = static_cast<Eigen::Index>(rows.size());
  const auto n = static_cast<Eigen::Index>(rows.front().q.size());
  Log& log = out.log;
  log.time.resize(R);
  log.q.resize(R, n);
  log.qd.resize(R, n);
  log.tau.resize(R, n);
  bool velocity = true;
  std::vector<bool> stale(rows.size(), false);
  for (Eigen::Index r = 0; r < R; ++r) {
    const Entry& e = rows[static_cast<std::size_t>(r)];
    log.time(r) = static_cast<double>(e.stamp - rows.front().stamp) * 1e-9;
    // Stamps 1 ns apart long after the first (a clock that jumped years) are one double.
    if (r > 0 && !(log.time(r) > log.time(r - 1)))
      throw DataError(input.string(), 0,
                      fmt::format("stamps {} and {} are too close to tell apart {} s after the first row (a clock "
                                  "that jumped?)",
                                  stamp_text(rows[static_cast<std::size_t>(r - 1)].stamp), stamp_text(e.stamp),
                                  number_text(log.time(r))));
    for (Eigen::Index c = 0; c < n; ++c) {
      const auto j = static_cast<std::size_t>(c);
      log.q(r, c) = e.q[j];
      log.qd(r, c) = e.qd[j];
      log.tau(r, c) = settings.effort == EffortKind::current ? e.tau[j] * settings.torque_constants[j] : e.tau[j];
    }
    velocity = velocity && whole(e.qd);
    out.lines.push_back(static_cast<int>(e.number));
    if (r > 0) {
      const Entry& p = rows[static_cast<std::size_t>(r - 1)];
      stale[static_cast<std::size_t>(r)] = p.q == e.q && p.tau == e.tau && (p.qd == e.qd || !whole(e.qd));
      if (stale[static_cast<std::size_t>(r)]) out.stale_lines.push_back(static_cast<int>(e.number));
    }
  }
  if (!velocity) {
    log.qd = differentiate_positions(log.time, log.q, stale);
    if (!log.qd.allFinite())
      throw DataError(input.string(), 0,
                      fmt::format("the velocity differentiated from position overflows (positions up to {:.3g}): no "
                                  "joint's position in SI units",
                                  log.q.cwiseAbs().maxCoeff()));
  }
  return velocity;
}

// What the import decided, for the user (remarks, the sidecar's notes) and import.yaml (columns).
void describe(const Gathered& got, const Merged& m, std::size_t files, bool velocity, const BagSettings& settings,
              const ImportTarget& target, ImportedLog& out) {
  const std::string stamps_from =
      settings.stamp == StampSource::header ? "header.stamp" : "the recorder's receive time (log_time)";
  std::string constants, others;
  for (double c : settings.torque_constants) constants += (constants.empty() ? "" : ", ") + number_text(c);
  for (const auto& [t, c] : got.other_topics)
    others += fmt::format("{}{} {}", others.empty() ? "; other topics: " : ", ", t, c);
  out.remarks.push_back(fmt::format("{} MCAP file{}, {} messages on {} (sensor_msgs/msg/JointState){}", files,
                                    files == 1 ? "" : "s", got.entries.size(), settings.topic, others));
  out.remarks.push_back(
      fmt::format("time from {}, 0 at the first row (stamp {})", stamps_from, stamp_text(m.rows.front().stamp)));
  out.remarks.push_back(fmt::format(
      "{} rows from {} stamps; {} partial stamps left out{}; {} duplicate messages", m.rows.size(), m.stamps(),
      m.partial, m.partial ? " (joints missing most: " + m.missing_most(target) + ")" : "", m.duplicates.size()));
  out.remarks.push_back("effort: " + (settings.effort == EffortKind::torque
                                          ? std::string("joint torque (N m) as published")
                                          : "motor current (A) times the torque constants [" + constants + "] N m/A"));
  out.remarks.push_back(velocity ? "velocity: measured (JointState.velocity)"
                                 : "velocity: differentiated from position (some messages carry none)");
  if (!got.ignored_names.empty())
    out.remarks.push_back("names the robot has not, ignored: " +
                          joined({got.ignored_names.begin(), got.ignored_names.end()}));
  for (const std::string& c : got.cut) out.remarks.push_back(c);
  for (std::size_t j = 0; j < target.joints.size(); ++j) {
    const std::string& name = target.joints[j];
    const std::string i = std::to_string(j + 1);
    out.columns["q" + i] = fmt::format("{} position[{}]", settings.topic, name);
    out.columns["qd" + i] =
        velocity ? fmt::format("{} velocity[{}]", settings.topic, name) : std::string("differentiated from q") + i;
    out.columns["tau" + i] = fmt::format(
        "{} effort[{}]{}", settings.topic, name,
        settings.effort == EffortKind::current ? " x " + number_text(settings.torque_constants[j]) + " N m/A" : "");
  }
}

}  // namespace

BagSettings bag_settings(const std::string& topic, const std::string& stamp, const std::string& effort,
                         const std::vector<double>& torque_constants, std::size_t joints, const fs::path& robot_yaml) {
  if (stamp != "header" && stamp != "receive")
    throw std::invalid_argument(fmt::format("stamp '{}': header or receive", stamp));
  if (effort != "torque" && effort != "current")
    throw std::invalid_argument(fmt::format("effort '{}': torque or current", effort));
  BagSettings b;
  b.topic = topic;
  b.stamp = stamp == "receive" ? StampSource::receive : StampSource::header;
  b.effort = effort == "current" ? EffortKind::current : EffortKind::torque;
  if (b.effort == EffortKind::torque) {
    if (!torque_constants.empty()) throw std::invalid_argument("torque constants go with effort as motor current");
    return b;
  }
  std::error_code ec;
  b.torque_constants = torque_constants.empty() && fs::is_regular_file(robot_yaml, ec)
                           ? robot_torque_constants(robot_yaml)
                           : torque_constants;
  if (b.torque_constants.size() == 1) b.torque_constants.assign(joints, b.torque_constants[0]);
  if (b.torque_constants.size() != joints)
    throw std::invalid_argument(fmt::format(
        "effort as motor current needs the joints' torque constants (N m/A): one for all joints or {}, or "
        "torque_constant on each joint of {}; {} given",
        joints, robot_yaml.empty() ? std::string("robot.yaml") : robot_yaml.string(), b.torque_constants.size()));
  return b;
}

ImportedLog import_bag(const fs::path& input, const BagSettings& settings, const ImportTarget& target) {
  const std::size_t n = target.joints.size();
  if (settings.effort == EffortKind::current && settings.torque_constants.size() != n)
    throw DataError(input.string(), 0,
                    fmt::format("effort as motor current needs a torque constant per joint ({}), {} given", n,
                                settings.torque_constants.size()));
  const std::vector<fs::path> files = bag_files(input);
  Gatherer g(input, settings, target);
  for (const fs::path& f : files) g.file(f);
  check_gathered(g.out, input, settings, target);
  const Merged m = merge_stamps(g.out, input, settings, target);
  ImportedLog out;
  out.input = input;
  out.rows = static_cast<int>(g.out.entries.size());
  out.duplicate_lines = m.duplicates;
  const bool velocity = fill_samples(m, input, settings, out);
  Log& log = out.log;
  log.meta.robot = target.robot;
  log.meta.trajectory = input.stem().string();
  log.meta.source = "robot";
  log.meta.joints = target.joints;
  log.meta.velocity = velocity ? Velocity::measured : Velocity::differentiated;
  log.meta.sample_time = median_sample_time(log.time, input.string());
  describe(g.out, m, files.size(), velocity, settings, target, out);
  log.meta.notes = "imported from ROS 2 bag " + input.filename().string();
  for (const std::string& r : out.remarks) log.meta.notes += "; " + r;
  return out;
}

}  // namespace symoro::io
