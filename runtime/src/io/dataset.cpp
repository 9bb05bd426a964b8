#include "symoro/io/dataset.hpp"

#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "symoro/io/yaml_text.hpp"

namespace symoro::io {

namespace {

// The manifest's keys, and its records' (dynid twin dataset: seed, trials, effects; dynid
// import: split, import, imported): a typo must not pass for one.
const std::vector<std::string> kManifestKeys = {"format", "robot",   "source", "twin",   "twin_overrides", "seed",
                                                "trials", "effects", "split",  "import", "imported",       "runs"};
const std::vector<std::string> kRunKeys = {"trajectory", "family", "trial", "file", "window"};
const std::vector<std::string> kImportKeys = {"inputs", "rows", "written", "stale_rows", "duplicate_rows"};
const std::vector<std::string> kImportedKeys = {"file",           "rows",        "stale_rows",
                                                "duplicate_rows", "sample_time", "velocity"};

// The given rows of `m`, in order.
Eigen::MatrixXd rows_of(const Eigen::MatrixXd& m, const std::vector<Eigen::Index>& rows) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), m.cols());
  if (m.cols() == 0) return out;  // no data: a row of it would offset a null pointer (fuzz_dataset)
  for (std::size_t i = 0; i < rows.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = m.row(rows[i]);
  return out;
}

}  // namespace

const DatasetRun& Dataset::find(const std::string& trajectory, int trial) const {
  for (const DatasetRun& r : runs)
    if (r.trajectory == trajectory && r.trial == trial) return r;
  throw DataError((dir / "dataset.yaml").string(), 0, fmt::format("no run of {} trial {}", trajectory, trial));
}

Dataset read_dataset(const std::filesystem::path& dir) {
  const auto manifest = dir / "dataset.yaml";
  if (!std::filesystem::exists(manifest))
    throw DataError(manifest.string(), 0,
                    "not found: a dataset folder holds dataset.yaml (made by dynid twin dataset or dynid import)");
  Dataset d;
  d.dir = std::filesystem::absolute(dir);
  const YAML::Node root = load_yaml_file(manifest);
  auto line = [](const YAML::Node& n) { return n.Mark().line + 1; };
  try {
    check_keys(root, kManifestKeys, manifest.string(), "dataset.yaml");
    if (!root["runs"] || !root["runs"].IsSequence())
      throw DataError(manifest.string(), line(root), "'runs' list missing");
    d.robot = root["robot"] ? root["robot"].as<std::string>() : "";
    if (root["robot"]) d.robot_line = line(root["robot"]);
    d.twin = root["twin"] ? root["twin"].as<std::string>() : "";
    d.source = root["source"] ? root["source"].as<std::string>() : "";
    if (root["twin_overrides"]) {  // kept in the dataset folder, so the hidden effects travel with it
      d.twin_overrides = (d.dir / root["twin_overrides"].as<std::string>()).string();
      if (!std::filesystem::exists(d.twin_overrides))
        throw DataError(manifest.string(), line(root["twin_overrides"]),
                        fmt::format("twin_overrides file {} does not exist", d.twin_overrides));
    }
    if (root["seed"] || root["trials"] || root["effects"]) {
      TwinDatasetRecord t;
      if (root["seed"]) t.seed = root["seed"].as<std::uint64_t>();
      if (root["trials"]) t.trials = root["trials"].as<int>();
      if (root["effects"]) t.effects = root["effects"].as<std::vector<std::string>>();
      d.twin_record = t;
    }
    if (root["split"]) d.split = root["split"].as<double>();
    if (const YAML::Node n = root["import"]) {
      check_keys(n, kImportKeys, manifest.string(), "import");
      ImportCounts c;
      for (auto [key, value] : {std::pair{"inputs", &c.inputs},
                                {"rows", &c.rows},
                                {"written", &c.written},
                                {"stale_rows", &c.stale_rows},
                                {"duplicate_rows", &c.duplicate_rows}})
        if (n[key]) *value = n[key].as<int>();
      d.import = c;
    }
    if (const YAML::Node list = root["imported"]) {
      if (!list.IsSequence()) throw DataError(manifest.string(), line(list), "imported: expected a list of logs");
      for (const YAML::Node& n : list) {
        check_keys(n, kImportedKeys, manifest.string(), "an imported log");
        ImportedFile f;
        if (n["file"]) f.file = n["file"].as<std::string>();
        for (auto [key, value] :
             {std::pair{"rows", &f.rows}, {"stale_rows", &f.stale_rows}, {"duplicate_rows", &f.duplicate_rows}})
          if (n[key]) *value = n[key].as<int>();
        if (n["sample_time"]) f.sample_time = n["sample_time"].as<double>();
        if (n["velocity"]) f.velocity = n["velocity"].as<std::string>();
        d.imported.push_back(std::move(f));
      }
    }
    for (const YAML::Node& r : root["runs"]) {
      check_keys(r, kRunKeys, manifest.string(), "a run");
      for (const char* key : {"trajectory", "family", "trial", "file"})
        if (!r[key]) throw DataError(manifest.string(), line(r), fmt::format("run without '{}'", key));
      // A log outside the folder was used without a word: a dataset is its folder (a link in it
      // reaches a log elsewhere, said where the user made it).
      const std::filesystem::path listed = std::filesystem::path(r["file"].as<std::string>()).lexically_normal();
      if (listed.empty()) throw DataError(manifest.string(), line(r["file"]), "file: a run needs its log's file name");
      if (listed.is_absolute() || *listed.begin() == "..")
        throw DataError(
            manifest.string(), line(r["file"]),
            fmt::format("file '{}' is outside the dataset folder: a dataset's logs are in its folder (copy the "
                        "log in, or link it there)",
                        r["file"].as<std::string>()));
      DatasetRun run{r["trajectory"].as<std::string>(), r["family"].as<std::string>(), r["trial"].as<int>(),
                     d.dir / listed};
      if (!std::filesystem::exists(run.file))
        throw DataError(manifest.string(), line(r), fmt::format("listed file {} does not exist", run.file.string()));
      if (const YAML::Node w = r["window"]) {
        if (!w.IsSequence() || w.size() != 2)
          throw DataError(manifest.string(), line(w), "window: expected [start, end] in seconds of log time");
        run.window_start = w[0].as<double>();
        run.window_end = w[1].as<double>();
        if (std::isnan(run.window_start) || std::isnan(run.window_end) || !(run.window_start < run.window_end))
          throw DataError(manifest.string(), line(w),
                          fmt::format("window: [{}, {}] is not an interval (start < end)",
                                      number_text(run.window_start), number_text(run.window_end)));
      }
      d.runs.push_back(std::move(run));
    }
  } catch (const YAML::Exception& e) {
    throw DataError(manifest.string(), e.mark.line + 1, e.msg);
  }
  return d;
}

namespace {

// A path as the manifest lists it: relative to the folder when it lies inside it.
std::string listed(const std::filesystem::path& dir, const std::filesystem::path& file) {
  if (!file.is_absolute()) return file.generic_string();
  const std::filesystem::path rel =
      file.lexically_normal().lexically_relative(std::filesystem::absolute(dir).lexically_normal());
  return rel.empty() || *rel.begin() == ".." ? file.generic_string() : rel.generic_string();
}

}  // namespace

void write_dataset(const Dataset& d) {
  std::string y = "format: symoro-dataset 1\n";
  if (!d.robot.empty()) y += "robot: " + yaml_quoted(d.robot) + "\n";
  if (!d.source.empty()) y += "source: " + yaml_quoted(d.source) + "\n";
  if (!d.twin.empty()) y += "twin: " + yaml_quoted(d.twin) + "\n";
  if (!d.twin_overrides.empty()) y += "twin_overrides: " + yaml_quoted(listed(d.dir, d.twin_overrides)) + "\n";
  if (d.twin_record) {
    y += fmt::format("seed: {}\ntrials: {}\neffects: [", d.twin_record->seed, d.twin_record->trials);
    for (std::size_t i = 0; i < d.twin_record->effects.size(); ++i)
      y += (i ? ", " : "") + yaml_quoted(d.twin_record->effects[i]);
    y += "]\n";
  }
  if (d.split > 0) y += "split: " + yaml_number(d.split) + "\n";
  if (d.import)
    y += fmt::format("import: {{inputs: {}, rows: {}, written: {}, stale_rows: {}, duplicate_rows: {}}}\n",
                     d.import->inputs, d.import->rows, d.import->written, d.import->stale_rows,
                     d.import->duplicate_rows);
  if (!d.imported.empty()) {
    y += "imported:\n";
    for (const ImportedFile& f : d.imported)
      y +=
          fmt::format("  - {{file: {}, rows: {}, stale_rows: {}, duplicate_rows: {}, sample_time: {}, velocity: {}}}\n",
                      yaml_quoted(f.file), f.rows, f.stale_rows, f.duplicate_rows, yaml_number(f.sample_time),
                      yaml_quoted(f.velocity));
  }
  y += "runs:\n";
  for (const DatasetRun& r : d.runs) {
    y += fmt::format("  - {{trajectory: {}, family: {}, trial: {}, file: {}", yaml_quoted(r.trajectory),
                     yaml_quoted(r.family), r.trial, yaml_quoted(listed(d.dir, r.file)));
    if (std::isfinite(r.window_start) || std::isfinite(r.window_end))
      y += fmt::format(", window: [{}, {}]", yaml_number(r.window_start), yaml_number(r.window_end));
    y += "}\n";
  }
  write_file_atomically(d.dir / "dataset.yaml", y);
}

Log read_run_log(const DatasetRun& run) {
  Log log = read_log(run.file);
  const bool whole =
      std::isinf(run.window_start) && run.window_start < 0 && std::isinf(run.window_end) && run.window_end > 0;
  log.meta.trajectory = run.trajectory;
  if (whole) return log;
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < log.samples(); ++k)
    if (run.window_start <= log.time[k] && log.time[k] < run.window_end) rows.push_back(k);
  if (rows.empty())
    throw DataError(run.file.string(), 0,
                    fmt::format("run {}: its window [{}, {}) s holds none of the log's samples ({} to {} s)",
                                run.trajectory, number_text(run.window_start), number_text(run.window_end),
                                number_text(log.time[0]), number_text(log.time[log.samples() - 1])));
  // The window's rows are contiguous (time increases): the file stays with the window.
  const auto file = std::make_shared<const Log>(std::move(log));
  Log window;
  window.meta = file->meta;
  window.file = file;
  window.file_row = rows.front();
  window.time.resize(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) window.time[static_cast<Eigen::Index>(i)] = file->time[rows[i]];
  window.q = rows_of(file->q, rows);
  window.qd = rows_of(file->qd, rows);
  window.tau = rows_of(file->tau, rows);
  window.q_ref = rows_of(file->q_ref, rows);
  window.qd_ref = rows_of(file->qd_ref, rows);
  window.qdd_ref = rows_of(file->qdd_ref, rows);
  return window;
}

void check_log_robot(const Log& log, const std::filesystem::path& csv, const std::string& robot, int joints) {
  if (!log.meta.robot.empty() && log.meta.robot != robot)
    throw DataError(metadata_path(csv).string(), 0,
                    fmt::format("the log is of robot '{}', the model of '{}'", log.meta.robot, robot));
  if (log.joints() != joints)
    throw DataError(csv.string(), 0,
                    fmt::format("the log has {} joints, the model of {} {}", log.joints(), robot, joints));
}

Log read_run_log(const DatasetRun& run, const std::string& robot, int joints) {
  Log log = read_run_log(run);
  if (!log.meta.robot.empty() && log.meta.robot != robot)
    throw DataError(
        metadata_path(run.file).string(), 0,
        fmt::format("run {}: the log is of robot '{}', the model of '{}'", run.trajectory, log.meta.robot, robot));
  if (log.joints() != joints)
    throw DataError(run.file.string(), 0,
                    fmt::format("run {}: the log has {} joints, the model {}", run.trajectory, log.joints(), joints));
  return log;
}

void check_dataset_robot(const Dataset& dataset, const std::string& robot) {
  if (dataset.robot.empty() || dataset.robot == robot) return;
  throw DataError((dataset.dir / "dataset.yaml").string(), dataset.robot_line,
                  fmt::format("the dataset was made for robot '{}', not '{}'", dataset.robot, robot));
}

std::vector<NamedLog> read_input_logs(const std::filesystem::path& input, const std::string& robot, int joints,
                                      int trial) {
  std::vector<NamedLog> out;
  if (std::filesystem::is_directory(input)) {
    const Dataset data = read_dataset(input);
    check_dataset_robot(data, robot);
    for (const auto& r : data.runs)
      if (r.trial == trial) out.push_back({r.trajectory, read_run_log(r, robot, joints)});
  } else {
    Log log = read_log(input);
    check_log_robot(log, input, robot, joints);
    out.push_back({input.stem().string(), std::move(log)});
  }
  return out;
}

}  // namespace symoro::io
