// Writes a CSV as a robot's own controller could export it, for the command-line tests of the
// any-robot workflow: `write_export <robot> <file> <seconds> <seed>` for rx90 or planar2r. The
// motion and torque come from the robot's generated model (synthetic_log.hpp) with Coulomb
// friction (in the truth; a `rigid` model lacks it), an offset of -0.06 N m on the last joint,
// noise and 5 % stale rows; columns stamp_ms, mode (text), <joint>_pos, _vel (deg, deg/s; m,
// m/s for a prismatic joint), <joint>_eff (N m; N).
#include <cstdio>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>

#include "synthetic_log.hpp"
#include "test_support.hpp"

namespace {

template <class Model>
int write(const std::string& file, double seconds, unsigned seed) {
  symoro::test::Random rng(23);
  const Eigen::Matrix<double, Model::np, 1> truth = Model::base_from_standard(symoro::test::random_standard_parameters<Model>(rng).s);
  const symoro::io::Log log =
      symoro::test::synthesize<Model>("export", truth, seconds, seed, 0.05, symoro::test::offset_on<Model>(Model::nq, -0.06));
  symoro::test::write_export_csv<Model>(log, file);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: write_export rx90|stanford_rrp <file.csv> <seconds> <seed>\n");
    return 2;
  }
  const std::string robot = argv[1];
  const double seconds = std::stod(argv[3]);
  const unsigned seed = static_cast<unsigned>(std::stoul(argv[4]));
  if (robot == "rx90") return write<symoro::rx90::Model>(argv[2], seconds, seed);
  if (robot == "stanford_rrp") return write<symoro::stanford_rrp::Model>(argv[2], seconds, seed);
  std::fprintf(stderr, "unknown robot %s\n", robot.c_str());
  return 2;
}
