// dynid: everything at run time for a robot of robots/ (--robot <name>): trajectories, the
// digital twin and its datasets (later: identification, diagnosis, the real arm).
#include <cstdio>
#include <exception>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "dynid_common.hpp"
#include "dynid_robots.hpp"
#include "symoro/error.hpp"
#include "symoro/parallel/farm.hpp"

namespace symoro::dynid {
bool Progress::isatty_stderr() { return ::isatty(2) == 1; }
}  // namespace symoro::dynid

int main(int argc, char** argv) {
  using namespace symoro::dynid;
  CLI::App app{"dynid: trajectories, digital twin and datasets for the robots of robots/"};
  app.require_subcommand(1);
  Common common;
  std::string known;
  for (const auto& r : robot_names()) known += (known.empty() ? "" : ", ") + r;
  app.footer("Robots: " + known);
  add_trajectory_commands(app, common);
  add_excite_commands(app, common);
  add_twin_commands(app, common);
  add_import_commands(app, common);
  add_preprocess_commands(app, common);
  add_identify_commands(app, common);
  add_diagnose_commands(app, common);
  add_compare_commands(app, common);
  add_control_commands(app, common);
  add_export_commands(app, common);
  add_predict_commands(app, common);
  add_observer_commands(app, common);
  add_payload_commands(app, common);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const symoro::DataError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    symoro::parallel::abort_job(1);  // under mpirun the other ranks would wait for this one
    return 1;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "dynid: error: %s\n", e.what());
    symoro::parallel::abort_job(2);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dynid: error: %s\n", e.what());
    symoro::parallel::abort_job(1);
    return 1;
  }
  return 0;
}
