// The CRANE-X7 twin's CAD standard parameters, exact or wrong by a random factor per link, as a
// standard-parameter YAML for `dynid identify --rescue-prior` (docs/identification.md: the
// rescue's prior). Usage: perturbed_cad_prior [spread, e.g. 0.3] > prior.yaml. Each link's
// inertial parameters are scaled alike (1 + U(-spread, spread), so the prior stays physically
// consistent), each drive parameter by its own factor; seed 11.
#include <cstdio>
#include <random>
#include <string>
#include <symoro/crane_x7.hpp>
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
using Model = symoro::crane_x7::Model;
int main(int argc, char** argv) {
  const double spread = argc > 1 ? std::stod(argv[1]) : 0.0;
  const auto c = symoro::twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Model::nq, "");
  auto s = symoro::twin::make_truth(symoro::robot::compiled_model<Model>(), c).standard;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-spread, spread);
  // One factor per link (a link's mass scaled scales its moments and inertia alike), plus a
  // per-entry factor for drives.
  double link_factor[16];
  for (double& f : link_factor) f = 1 + u(rng);
  std::printf("parameters:\n");
  for (int k = 0; k < Model::ns; ++k) {
    const auto& p = Model::standard_parameters[k];
    const std::string fam = p.family;
    double v = s(k);
    if (fam == "IA" || fam == "FV" || fam == "FS")
      v *= 1 + u(rng);
    else
      v *= link_factor[p.joint];
    std::printf("  - {name: \"%s\", value: %.17g}\n", p.name, v);
  }
}
