// Import and identification of one controller export: a 20,000-sample (20 s at 1 kHz) log of
// the CRANE-X7 (7 arm joints and the gripper: 8 joints) in degrees and milliseconds with stale
// rows, as `dynid import` and `dynid identify --interval 10` run it without a controller
// description (OLS, all-pose audit, conditional SDP, selection, final audit). Wall time:
//   build/bench/bench_import_identify --benchmark_min_time=1x   (Iterations(3) below)
#include <filesystem>

#include <unistd.h>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <symoro/crane_x7.hpp>

#include "symoro/study/study.hpp"
#include "symoro/io/import.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "synthetic_log.hpp"

namespace {

using Full = symoro::crane_x7::Model;
using Model = symoro::crane_x7::reduced::Model;
const std::filesystem::path kDir =
    std::filesystem::temp_directory_path() / ("symoro_bench_import_" + std::to_string(::getpid()));

// The export, written once: the twin's true parameters, 5 % stale rows, noise.
const std::filesystem::path& export_csv() {
  static const std::filesystem::path file = [] {
    std::filesystem::create_directories(kDir);
    const auto twin = symoro::twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Full::nq);
    const Eigen::Matrix<double, Full::np, 1> phi =
        symoro::twin::make_truth(symoro::robot::compiled_model<Full>(), twin).phi;
    const symoro::io::Log log = symoro::test::synthesize<Full>("arm", phi, 20.0, 3, 0.01);
    const auto f = kDir / "export.csv";
    symoro::test::write_export_csv<Full>(log, f);
    return f;
  }();
  return file;
}

symoro::io::DatasetImport import_spec() {
  symoro::io::DatasetImport im;
  im.target.robot = "crane_x7";
  for (const auto& J : Full::joints) im.target.joints.emplace_back(J.name);
  im.mapping.time = "stamp_ms";
  im.mapping.q = "{name}_pos";
  im.mapping.qd = "{name}_vel";
  im.mapping.tau = "{name}_eff";
  im.mapping.time_unit = symoro::io::TimeUnit::ms;
  im.mapping.angle_unit = symoro::io::AngleUnit::deg;
  im.inputs.push_back({export_csv(), "arm", false});
  im.split = 0.7;
  return im;
}

void BM_Import(benchmark::State& state) {
  const auto im = import_spec();
  for (auto _ : state) {
    std::filesystem::remove_all(kDir / "data");
    benchmark::DoNotOptimize(symoro::io::import_dataset(kDir / "data", im));
  }
}
BENCHMARK(BM_Import)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

void BM_ImportAndIdentify(benchmark::State& state) {
  const auto im = import_spec();
  for (auto _ : state) {
    std::filesystem::remove_all(kDir / "data");
    std::filesystem::remove_all(kDir / "study");
    symoro::io::import_dataset(kDir / "data", im);
    symoro::study::StudyOptions o;
    o.data = kDir / "data";
    o.out = kDir / "study";
    o.intervals = {0.010};
    symoro::study::Study study(symoro::identify::identification_model<Model>(), o, symoro::study::ClosedLoopSource{});
    const auto r = study.run();
    state.counters["accepted"] = r.accepted;
  }
}
BENCHMARK(BM_ImportAndIdentify)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace
