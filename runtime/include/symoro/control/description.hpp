// The experiment's controller description, robots/<robot>/controller.yaml: the loop period,
// the bus delay, and the paper's FF+PD (realization parameters, bandwidths, damping ratios,
// pseudo-differentiation). One file that identification (CLIE, closed-loop validation), the
// digital twin and the real arm's loop all read; a robot without it is still identifiable
// (OLS, audit, SDP), only the closed-loop stages are skipped.
//
//   format: symoro-controller 1
//   period: 0.001                  # s
//   pseudo_derivative_time: 0.002  # s, Tf of s / (1 + Tf s)
//   communication_delay: 0.0009    # s, sampling to the command taking effect (< period)
//   realization: {inertia: [...], damping: [...]}  # M_hat (kg m^2 > 0), D_hat (N m s/rad >= 0)
//   bandwidth: [...]               # rad/s > 0: K_P = w^2, K_V = 2 zeta w
//   damping_ratio: [...]           # > 0
#pragma once

#include <filesystem>
#include <string>

#include <Eigen/Core>

#include "symoro/control/ffpd.hpp"

namespace symoro::control {

struct ControllerDescription {
  std::string path;  // the file it was read from ("" when built in code)
  double period = 0.001;
  double pseudo_derivative_time = 0.002;
  double communication_delay = 0.0009;
  Eigen::VectorXd realization_inertia, realization_damping;  // M-hat, D-hat
  Eigen::VectorXd bandwidth, damping_ratio;                  // -> K_P = w^2, K_V = 2 zeta w

  FfpdGains gains() const;
};

// The file's name in a robot folder.
inline const char* controller_file_name() { return "controller.yaml"; }

// Reads and validates a controller description for `joints` joints. Throws DataError naming the
// file and line: a missing or unknown key, a list of the wrong length, a value out of range, a
// delay not shorter than the period.
ControllerDescription read_controller_description(const std::filesystem::path& path, int joints);

}  // namespace symoro::control
