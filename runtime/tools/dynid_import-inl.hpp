// dynid import's body for one robot (included by the generated units only): the exported logs
// mapped onto the robot's joints and written as a dataset.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "dynid_import.hpp"
#include "symoro/io/import.hpp"

namespace symoro::dynid {

namespace import_detail {

// The command line's settings over the mapping file's (or the defaults).
inline io::ImportMapping mapping_of(const ImportOptions& o) {
  io::ImportMapping m = o.mapping.empty() ? io::ImportMapping{} : io::read_import_mapping(o.mapping);
  io::apply_settings(m, {o.time, o.q, o.qd, o.tau, o.q_ref, o.qd_ref, o.qdd_ref, o.time_unit, o.angle, o.header,
                         o.delimiter, o.torque_scale});
  if (m.time.empty() || m.q.empty() || m.tau.empty())
    throw UsageError("say which columns hold time, q and tau: --time, --q, --tau, or --mapping map.yaml");
  return m;
}

}  // namespace import_detail

template <class Full, class Model>
void ImportCommand::run(const Common& common, const ImportOptions& o) {
  io::DatasetImport di;
  di.target = io::import_target(common.robot, joint_list<Model>());
  di.mapping = import_detail::mapping_of(o);
  di.split = o.split;
  di.allow_implausible = o.allow_implausible;
  if (!o.names.empty() && o.names.size() != o.inputs.size())
    throw UsageError(fmt::format("--name: {} names for {} input files", o.names.size(), o.inputs.size()));
  for (const std::string& h : o.heldout)
    if (std::find(o.inputs.begin(), o.inputs.end(), h) == o.inputs.end())
      throw UsageError(fmt::format("--heldout {}: not one of the input files", h));
  for (std::size_t i = 0; i < o.inputs.size(); ++i)
    di.inputs.push_back({o.inputs[i], o.names.empty() ? "" : o.names[i],
                         std::find(o.heldout.begin(), o.heldout.end(), o.inputs[i]) != o.heldout.end()});
  const io::DatasetImportResult r = io::import_dataset(o.out, di);
  for (const io::ImportedLog& l : r.logs) {
    const io::Log& log = l.log;
    fmt::print("{}: {} rows -> {}.csv: {} samples over {:.3f} s, sample time {:g} ms (median), {} stale rows kept, "
               "{} duplicates dropped, velocity {}\n",
               l.input.string(), l.rows, log.meta.trajectory, log.samples(), log.time[log.samples() - 1] - log.time[0],
               log.meta.sample_time * 1e3, l.stale_lines.size(), l.duplicate_lines.size(),
               log.meta.velocity == io::Velocity::measured ? "measured" : "differentiated from q");
    if (!l.stale_lines.empty())
      fmt::print("  stale rows (same state as the row before, new stamp) on lines {}{}\n", l.stale_lines.front(),
                 l.stale_lines.size() > 1 ? fmt::format(" .. {}", l.stale_lines.back()) : "");
  }
  for (const auto& run : r.runs) {
    fmt::print("run {} (family {}): {}", run.trajectory, run.family, run.file.filename().string());
    if (std::isfinite(run.window_start) || std::isfinite(run.window_end))
      fmt::print(", window [{:.6g}, {:.6g}) s", run.window_start, run.window_end);
    fmt::print("\n");
  }
  fmt::print("dataset: {} (mapping kept in import.yaml)\n", r.dataset.string());
}

}  // namespace symoro::dynid
