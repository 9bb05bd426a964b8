#include "symoro/identify/dataset.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"

namespace symoro::identify {

const DatasetRun& Dataset::find(const std::string& trajectory, int trial) const {
  for (const DatasetRun& r : runs)
    if (r.trajectory == trajectory && r.trial == trial) return r;
  throw DataError((dir / "dataset.yaml").string(), 0, fmt::format("no run of {} trial {}", trajectory, trial));
}

Dataset read_dataset(const std::filesystem::path& dir) {
  const auto manifest = dir / "dataset.yaml";
  if (!std::filesystem::exists(manifest))
    throw DataError(manifest.string(), 0, "not found: a dataset folder holds dataset.yaml (made by dynid twin dataset)");
  Dataset d;
  d.dir = std::filesystem::absolute(dir);
  YAML::Node root;
  try {
    root = YAML::LoadFile(manifest.string());
  } catch (const YAML::Exception& e) {
    throw DataError(manifest.string(), e.mark.line + 1, e.msg);
  }
  auto line = [](const YAML::Node& n) { return n.Mark().line + 1; };
  try {
    if (!root["runs"] || !root["runs"].IsSequence()) throw DataError(manifest.string(), line(root), "'runs' list missing");
    d.robot = root["robot"] ? root["robot"].as<std::string>() : "";
    d.twin = root["twin"] ? root["twin"].as<std::string>() : "";
    if (root["twin_overrides"]) {  // kept in the dataset folder, so the hidden effects travel with it
      d.twin_overrides = (d.dir / root["twin_overrides"].as<std::string>()).string();
      if (!std::filesystem::exists(d.twin_overrides))
        throw DataError(manifest.string(), line(root["twin_overrides"]),
                        fmt::format("twin_overrides file {} does not exist", d.twin_overrides));
    }
    for (const YAML::Node& r : root["runs"]) {
      for (const char* key : {"trajectory", "family", "trial", "file"})
        if (!r[key]) throw DataError(manifest.string(), line(r), fmt::format("run without '{}'", key));
      DatasetRun run{r["trajectory"].as<std::string>(), r["family"].as<std::string>(), r["trial"].as<int>(),
                     d.dir / r["file"].as<std::string>()};
      if (!std::filesystem::exists(run.file))
        throw DataError(manifest.string(), line(r), fmt::format("listed file {} does not exist", run.file.string()));
      d.runs.push_back(std::move(run));
    }
  } catch (const YAML::Exception& e) {
    throw DataError(manifest.string(), e.mark.line + 1, e.msg);
  }
  return d;
}

}  // namespace symoro::identify
