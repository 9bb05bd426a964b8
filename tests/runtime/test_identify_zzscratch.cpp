// Scratch (not committed)
#include <cstdio>
#include <cfenv>
#include <xmmintrin.h>
#include <gtest/gtest.h>
#include <symoro/crane_x7.hpp>
#include "symoro/identify/study.hpp"
namespace {
using namespace symoro;
using Model = crane_x7::reduced::Model;
TEST(Scratch, Mxcsr) {
  const auto inertia = identify::make_inertia_function<Model>();
  const auto domain = identify::audit_domain<Model>();
  Eigen::VectorXd phi = Eigen::VectorXd::Constant(Model::np, 0.01);
  std::printf("mxcsr before %x, round %d\n", _mm_getcsr(), fegetround());
  identify::audit_pd(*inertia, phi, domain);
  std::printf("mxcsr after audit %x, round %d\n", _mm_getcsr(), fegetround());
  std::vector<Eigen::VectorXd> poses{Eigen::VectorXd::Zero(Model::nq)};
  identify::project_on_poses(*inertia, -phi, poses, 0.001);
  std::printf("mxcsr after csdp %x, round %d\n", _mm_getcsr(), fegetround());
  fenv_t env; fegetenv(&env);
  unsigned short cw; __asm__ volatile("fnstcw %0" : "=m"(cw));
  std::printf("x87 cw %x\n", cw);
}
}  // namespace
