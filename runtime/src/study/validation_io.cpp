#include "symoro/study/validation_io.hpp"

#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/atomic_file.hpp"
#include "yaml_vector.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::study {

namespace {

constexpr const char* kFormat = "symoro-validation 1";
// Per joint, in this order after the time column.
constexpr const char* kColumns[] = {"q", "qd", "qdd", "measured", "clie", "accepted"};
constexpr int kPerJoint = 6;

std::string csv_name(const std::string& trajectory) { return trajectory + ".csv"; }

// time, q_1..n, qd_1..n, qdd_1..n, measured_1..n, clie_1..n, accepted_1..n: one row per sample.
std::string series_csv(const ValidationRecord& v) {
  const Eigen::Index n = v.tau_measured.cols(), rows = v.tau_measured.rows();
  std::string out = "time";
  for (const char* what : kColumns)
    for (Eigen::Index j = 0; j < n; ++j) out += fmt::format(",{}_{}", what, j + 1);
  out += '\n';
  auto cell = [](const Eigen::MatrixXd& m, Eigen::Index i, Eigen::Index j) {
    return i < m.rows() && j < m.cols() ? m(i, j) : std::numeric_limits<double>::quiet_NaN();
  };
  for (Eigen::Index i = 0; i < rows; ++i) {
    io::append_number(out, i < v.time.size() ? v.time(i) : std::numeric_limits<double>::quiet_NaN());
    for (const Eigen::MatrixXd* m : {&v.q, &v.qd, &v.qdd, &v.tau_measured, &v.tau_clie, &v.tau_rescue})
      for (Eigen::Index j = 0; j < n; ++j) {
        out += ',';
        io::append_number(out, cell(*m, i, j));
      }
    out += '\n';
  }
  return out;
}

void read_series(const std::filesystem::path& file, int joints, ValidationRecord& v) {
  std::ifstream in(file);
  if (!in) throw DataError(file.string(), 0, "cannot open the validation series (was the study's validation written?)");
  std::string line;
  std::vector<std::vector<double>> rows;
  const std::size_t columns = 1 + kPerJoint * static_cast<std::size_t>(joints);
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) {
      if (line.rfind("time,q_1,", 0) != 0) throw DataError(file.string(), 1, "expected the header 'time,q_1,...'");
      continue;
    }
    if (line.empty()) continue;
    std::vector<double> row;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::string_view text(line.data() + start, (comma == std::string::npos ? line.size() : comma) - start);
      double value = 0;
      if (io::parse_number(text, value) != io::NumberParse::ok)
        throw DataError(file.string(), number, fmt::format("column {}: '{}' is not a number", row.size() + 1, text));
      row.push_back(value);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (row.size() != columns)
      throw DataError(
          file.string(), number,
          fmt::format("{} columns, expected {} (time and {} x {} joints)", row.size(), columns, kPerJoint, joints));
    rows.push_back(std::move(row));
  }
  const Eigen::Index r = static_cast<Eigen::Index>(rows.size());
  v.time.resize(r);
  Eigen::MatrixXd* blocks[] = {&v.q, &v.qd, &v.qdd, &v.tau_measured, &v.tau_clie, &v.tau_rescue};
  for (Eigen::MatrixXd* m : blocks) m->resize(r, joints);
  for (Eigen::Index i = 0; i < r; ++i) {
    v.time(i) = rows[i][0];
    for (int b = 0; b < kPerJoint; ++b)
      for (int j = 0; j < joints; ++j) (*blocks[b])(i, j) = rows[i][1 + b * joints + j];
  }
}

// yaml-cpp's marks are 0-based; DataError's lines are 1-based.
int line_of(const YAML::Node& n) { return n.Mark().line >= 0 ? n.Mark().line + 1 : 0; }

const YAML::Node required(const YAML::Node& map, const char* key, const std::string& file) {
  const YAML::Node n = map[key];
  if (!n) throw DataError(file, line_of(map), fmt::format("missing '{}'", key));
  return n;
}

template <class T>
T as(const YAML::Node& n, const char* key, const std::string& file) {
  try {
    return required(n, key, file).as<T>();
  } catch (const YAML::Exception&) {
    throw DataError(file, line_of(n[key]), fmt::format("'{}' has the wrong type", key));
  }
}

Eigen::VectorXd vec(const YAML::Node& map, const char* key, const std::string& file, bool optional = false) {
  const YAML::Node n = map[key];
  if (!n && optional) return {};
  if (!n || !n.IsSequence())
    throw DataError(file, line_of(n ? n : map), fmt::format("'{}' must be a list of numbers", key));
  Eigen::VectorXd v(static_cast<Eigen::Index>(n.size()));
  for (std::size_t i = 0; i < n.size(); ++i) {
    try {
      v(static_cast<Eigen::Index>(i)) = n[i].as<double>();
    } catch (const YAML::Exception&) {
      throw DataError(file, line_of(n[i]), fmt::format("'{}' entry {} is not a number", key, i + 1));
    }
  }
  return v;
}

}  // namespace

std::vector<std::filesystem::path> write_validation(const StudyResult& study, const std::filesystem::path& study_dir) {
  std::vector<std::filesystem::path> files;
  if (study.validation.empty()) return files;
  std::filesystem::create_directories(study_dir / "validation");
  for (const auto& v : study.validation) {
    const auto file = study_dir / "validation" / csv_name(v.trajectory);
    io::write_file_atomically(file, series_csv(v));
    files.push_back(file);
  }
  YAML::Emitter y;
  y.SetDoublePrecision(17);
  y << YAML::BeginMap;
  y << YAML::Key << "format" << YAML::Value << kFormat;
  y << YAML::Key << "robot" << YAML::Value << study.robot;
  y << YAML::Key << "model" << YAML::Value << study.model;
  const bool has_run = study.selection.run >= 0 && study.selection.run < static_cast<int>(study.runs.size());
  y << YAML::Key << "selected_run" << YAML::Value << (has_run ? study.runs[study.selection.run].id() : std::string());
  y << YAML::Key << "accepted" << YAML::Value << study.accepted;
  y << YAML::Key << "rescued" << YAML::Value << study.rescued;
  y << YAML::Key << "names" << YAML::Value << YAML::Flow << study.names;
  y << YAML::Key << "units" << YAML::Value << YAML::Flow << study.units;
  detail::put_vector(y, "parameters", study.phi_rescue);
  if (study.truth.size() > 0) detail::put_vector(y, "truth", study.truth);
  y << YAML::Key << "trajectories" << YAML::Value << YAML::BeginSeq;
  for (const auto& v : study.validation) {
    y << YAML::BeginMap;
    y << YAML::Key << "trajectory" << YAML::Value << v.trajectory;
    y << YAML::Key << "interval" << YAML::Value << v.interval;
    if (v.edge_samples > 0) y << YAML::Key << "edge_samples" << YAML::Value << v.edge_samples;
    y << YAML::Key << "kind" << YAML::Value << v.kind;
    y << YAML::Key << "note" << YAML::Value << v.note;
    y << YAML::Key << "joints" << YAML::Value << static_cast<int>(v.tau_measured.cols());
    y << YAML::Key << "rmse_clie" << YAML::Value << v.rmse_clie;
    y << YAML::Key << "rmse_accepted" << YAML::Value << v.rmse_rescue;
    y << YAML::Key << "mne_clie" << YAML::Value << v.mne_clie;
    y << YAML::Key << "mne_accepted" << YAML::Value << v.mne_rescue;
    detail::put_vector(y, "rmse_joint_clie", v.rmse_joint_clie);
    detail::put_vector(y, "rmse_joint_accepted", v.rmse_joint_rescue);
    detail::put_vector(y, "nrmse_joint_accepted", v.nrmse_joint_rescue);
    if (std::isfinite(v.raw_rmse_rescue)) {
      y << YAML::Key << "raw_rmse_clie" << YAML::Value << v.raw_rmse_clie;
      y << YAML::Key << "raw_rmse_accepted" << YAML::Value << v.raw_rmse_rescue;
      detail::put_vector(y, "raw_rmse_joint_accepted", v.raw_rmse_joint_rescue);
      if (v.raw_floor_joint.size() > 0) detail::put_vector(y, "raw_floor_joint", v.raw_floor_joint);
      y << YAML::Key << "raw_filter" << YAML::Value << v.raw_filter;
    }
    if (std::isfinite(v.band_coverage)) {
      y << YAML::Key << "band_coverage" << YAML::Value << v.band_coverage;
      detail::put_vector(y, "band_coverage_joint", v.band_coverage_joint);
    }
    y << YAML::Key << "series" << YAML::Value << "validation/" + csv_name(v.trajectory);
    y << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::EndMap;
  const auto file = study_dir / "validation.yaml";
  io::write_file_atomically(file, std::string(y.c_str()) + "\n");
  files.push_back(file);
  return files;
}

StudyValidation read_validation(const std::filesystem::path& study_dir) {
  const auto path = study_dir / "validation.yaml";
  const std::string file = path.string();
  if (!std::filesystem::exists(path))
    throw DataError(file, 0,
                    "not found: is this an identification study folder (dynid identify -o) with held-out "
                    "validation trajectories?");
  YAML::Node root;
  try {
    root = io::load_yaml_file(file);  // anchors, aliases and a second document refused
  } catch (const YAML::ParserException& e) {
    throw DataError(file, e.mark.line + 1, e.msg);
  }
  if (!root.IsMap()) throw DataError(file, 1, "expected a map");
  if (as<std::string>(root, "format", file) != kFormat)
    throw DataError(file, line_of(root["format"]), fmt::format("unknown format (expected '{}')", kFormat));
  StudyValidation s;
  s.robot = as<std::string>(root, "robot", file);
  s.model = as<std::string>(root, "model", file);
  s.selected_run = as<std::string>(root, "selected_run", file);
  s.accepted = as<bool>(root, "accepted", file);
  s.rescued = as<bool>(root, "rescued", file);
  s.names = as<std::vector<std::string>>(root, "names", file);
  s.units = as<std::vector<std::string>>(root, "units", file);
  s.phi = vec(root, "parameters", file);
  s.truth = vec(root, "truth", file, true);
  if (s.phi.size() != static_cast<Eigen::Index>(s.names.size()))
    throw DataError(file, line_of(root["parameters"]),
                    fmt::format("{} parameters for {} names", s.phi.size(), s.names.size()));
  const YAML::Node list = required(root, "trajectories", file);
  if (!list.IsSequence()) throw DataError(file, line_of(list), "'trajectories' must be a list");
  for (const YAML::Node& t : list) {
    ValidationRecord v;
    v.trajectory = as<std::string>(t, "trajectory", file);
    v.interval = as<double>(t, "interval", file);
    v.edge_samples = t["edge_samples"] ? as<int>(t, "edge_samples", file) : 0;
    v.kind = t["kind"] ? as<std::string>(t, "kind", file) : "closed-loop";  // studies before open-loop validation
    v.note = t["note"] ? as<std::string>(t, "note", file) : "";
    if (v.kind != "closed-loop" && v.kind != "open-loop")
      throw DataError(file, line_of(t["kind"]),
                      fmt::format("'kind' must be closed-loop or open-loop, not '{}'", v.kind));
    const int joints = as<int>(t, "joints", file);
    if (joints < 1) throw DataError(file, line_of(t["joints"]), "'joints' must be positive");
    v.rmse_clie = as<double>(t, "rmse_clie", file);
    v.rmse_rescue = as<double>(t, "rmse_accepted", file);
    v.mne_clie = as<double>(t, "mne_clie", file);
    v.mne_rescue = as<double>(t, "mne_accepted", file);
    v.rmse_joint_clie = vec(t, "rmse_joint_clie", file);
    v.rmse_joint_rescue = vec(t, "rmse_joint_accepted", file);
    v.nrmse_joint_rescue = vec(t, "nrmse_joint_accepted", file, true);
    if (t["raw_rmse_accepted"]) {  // studies before raw-torque validation have none
      v.raw_rmse_clie = as<double>(t, "raw_rmse_clie", file);
      v.raw_rmse_rescue = as<double>(t, "raw_rmse_accepted", file);
      v.raw_rmse_joint_rescue = vec(t, "raw_rmse_joint_accepted", file, true);
      v.raw_floor_joint = vec(t, "raw_floor_joint", file, true);  // studies before it have none
      v.raw_filter = t["raw_filter"] ? as<std::string>(t, "raw_filter", file) : "";
    }
    if (t["band_coverage"]) {  // studies before prediction bands have none
      v.band_coverage = as<double>(t, "band_coverage", file);
      v.band_coverage_joint = vec(t, "band_coverage_joint", file, true);
    }
    read_series(study_dir / as<std::string>(t, "series", file), joints, v);
    s.records.push_back(std::move(v));
  }
  return s;
}

}  // namespace symoro::study
