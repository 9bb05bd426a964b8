// A dataset folder from imported files: one log per input, import.yaml (the mapping and what
// each input gave), dataset.yaml last (docs/dataset.md). Every input is checked before the
// first file is written, and no existing file is replaced.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "symoro/error.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/folder_lock.hpp"
#include "symoro/io/import.hpp"
#include "symoro/io/import_bag.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_text.hpp"

namespace symoro::io {

namespace {

std::string line_list(const std::vector<int>& lines) {
  std::string out = "[";
  for (std::size_t i = 0; i < lines.size(); ++i) out += (i ? ", " : "") + std::to_string(lines[i]);
  return out + "]";
}

bool valid_name(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return false;
  for (char c : name)
    if (c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20) return false;
  return true;
}

namespace fs = std::filesystem;

// Every input read, checked and named, split into fitting and held-out runs when asked.
DatasetImportResult read_inputs(const fs::path& out, const DatasetImport& import) {
  DatasetImportResult result;
  std::set<std::string> names;
  for (const ImportInput& in : import.inputs) {
    ImportedLog imported = is_bag(in.file) ? import_bag(in.file, import.bag, import.target)
                                           : import_log(in.file, import.mapping, import.target);
    // A bag is in SI units (REP 103): checked as radians and seconds.
    if (!import.allow_implausible)
      check_plausible(imported, is_bag(in.file) ? ImportMapping{} : import.mapping, import.target);
    if (imported.log.meta.velocity == Velocity::measured)
      imported.remarks.push_back(detail::velocity_remark(imported.log));
    const std::string name = in.name.empty() ? in.file.stem().string() : in.name;
    if (!valid_name(name))
      throw DataError(in.file.string(), 0, fmt::format("'{}' cannot name a run (a file name)", name));
    imported.log.meta.trajectory = name;
    const fs::path csv = out / (name + ".csv");
    const bool split = import.split > 0 && !in.heldout;
    for (const std::string& run :
         split ? std::vector<std::string>{name, name + "_heldout"} : std::vector<std::string>{name})
      if (!names.insert(run).second)
        throw DataError(in.file.string(), 0, fmt::format("run name '{}' is used twice (name the inputs apart)", run));
    const Log& log = imported.log;
    if (!split) {
      result.runs.push_back({name, in.heldout ? kHeldOutFamily : "F", csv, -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::infinity()});
    } else {
      // By time: the first `split` of the run's span fits, the rest is held out.
      const double t0 = log.time[0], t1 = log.time[log.samples() - 1];
      const double cut = t0 + import.split * (t1 - t0);
      const Eigen::Index fitting = (log.time.array() < cut).count(), heldout = log.samples() - fitting;
      // Fewer than 4 samples cannot even be differentiated (--split 1e-9 leaves the first one).
      constexpr Eigen::Index min_part = 4;
      if (fitting < min_part || heldout < min_part)
        throw DataError(in.file.string(), 0,
                        fmt::format("split {} at {} s leaves {} of the {} samples in the {} part; each part needs at "
                                    "least {}",
                                    import.split, number_text(cut), std::min(fitting, heldout), log.samples(),
                                    fitting < min_part ? "fitting" : "held-out", min_part));
      result.runs.push_back({name, "F", csv, t0, cut});
      result.runs.push_back({name + "_heldout", kHeldOutFamily, csv, cut, std::numeric_limits<double>::infinity()});
    }
    result.logs.push_back(std::move(imported));
  }
  return result;
}

// import.yaml: the mapping (reusable as --mapping) and what each input gave.
std::string import_record(const DatasetImport& import, const DatasetImportResult& result) {
  std::string text = import_mapping_yaml(import.mapping);
  text +=
      fmt::format("imported:\n  robot: {}\n  split: {}\n", yaml_quoted(import.target.robot), number_text(import.split));
  if (std::any_of(import.inputs.begin(), import.inputs.end(), [](const ImportInput& i) { return is_bag(i.file); })) {
    const BagSettings& b = import.bag;
    std::string k;
    for (double c : b.torque_constants) k += (k.empty() ? "" : ", ") + number_text(c);
    text += fmt::format("  bag: {{topic: {}, stamp: {}, effort: {}, torque_constants: [{}]}}\n", yaml_quoted(b.topic),
                        b.stamp == StampSource::header ? "header" : "receive",
                        b.effort == EffortKind::torque ? "torque" : "current", k);
  }
  text += "  inputs:\n";
  for (const ImportedLog& l : result.logs) {
    text += fmt::format("    - input: {}\n      log: {}\n      rows: {}\n      written: {}\n",
                        yaml_quoted(fs::absolute(l.input).string()), yaml_quoted(l.log.meta.trajectory + ".csv"),
                        l.rows, l.log.samples());
    text +=
        fmt::format("      stale_rows: {}\n      stale_lines: {}\n", l.stale_lines.size(), line_list(l.stale_lines));
    text += fmt::format("      duplicate_rows: {}\n      duplicate_lines: {}\n", l.duplicate_lines.size(),
                        line_list(l.duplicate_lines));
    text +=
        fmt::format("      sample_time: {}\n      velocity: {}\n      columns:\n", number_text(l.log.meta.sample_time),
                    l.log.meta.velocity == Velocity::measured ? "measured" : "differentiated");
    for (const auto& [column, source] : l.columns) text += fmt::format("        {}: {}\n", column, yaml_quoted(source));
    if (!l.remarks.empty()) text += "      remarks:\n";
    for (const std::string& r : l.remarks) text += fmt::format("        - {}\n", yaml_quoted(r));
  }
  return text;
}

// dataset.yaml's content: the runs and what the import read.
Dataset imported_dataset(const fs::path& out, const DatasetImport& import, const DatasetImportResult& result) {
  Dataset d;
  d.dir = out;
  d.robot = import.target.robot;
  d.source = "imported";
  d.split = import.split;
  d.import.emplace();
  d.import->inputs = static_cast<int>(result.logs.size());
  for (const ImportedLog& l : result.logs) {
    d.import->rows += l.rows;
    d.import->written += l.log.samples();
    d.import->stale_rows += static_cast<int>(l.stale_lines.size());
    d.import->duplicate_rows += static_cast<int>(l.duplicate_lines.size());
    d.imported.push_back({l.log.meta.trajectory + ".csv", l.rows, static_cast<int>(l.stale_lines.size()),
                          static_cast<int>(l.duplicate_lines.size()), l.log.meta.sample_time,
                          l.log.meta.velocity == Velocity::measured ? "measured" : "differentiated"});
  }
  for (const DatasetImportResult::Run& r : result.runs)
    d.runs.push_back({r.trajectory, r.family, 1, r.file.filename(), r.window_start, r.window_end});
  return d;
}

}  // namespace

DatasetImportResult import_dataset(const std::filesystem::path& out, const DatasetImport& import) {
  if (import.inputs.empty()) throw DataError(out.string(), 0, "nothing to import: no input files");
  if (!(import.split >= 0 && import.split < 1))
    throw DataError(import.mapping.origin, 0,
                    fmt::format("split {} is not a fraction in (0, 1) (0: no split)", import.split));
  DatasetImportResult result = read_inputs(out, import);

  // One import into a folder at a time (two at once both passed the check below and one input
  // was lost), then never replace a file: an earlier import or recording stays as it was.
  const FolderLock lock(out, "dynid import");
  const fs::path manifest = out / "dataset.yaml", record = out / "import.yaml";
  std::vector<fs::path> targets{manifest, record};
  for (const ImportedLog& l : result.logs) {
    const fs::path csv = out / (l.log.meta.trajectory + ".csv");
    targets.push_back(csv);
    targets.push_back(metadata_path(csv));
  }
  for (const fs::path& t : targets)
    if (fs::exists(t))
      throw DataError(t.string(), 0, "exists already; the importer never replaces a file (choose a new folder)");
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw DataError(out.string(), 0, "cannot create the dataset folder: " + ec.message());

  for (const ImportedLog& l : result.logs) write_log(out / (l.log.meta.trajectory + ".csv"), l.log);

  write_file_atomically(record, import_record(import, result));
  // dataset.yaml last: it lists only files already in place.
  write_dataset(imported_dataset(out, import, result));
  result.dataset = manifest;
  return result;
}

}  // namespace symoro::io
