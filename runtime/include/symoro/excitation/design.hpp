// Optimized excitation for any robot (issue 29): a periodic finite Fourier series per joint
// (Swevers et al., 1997; trajectory/fourier.hpp) that maximizes D-optimality, log det of the
// column-scaled W'W of the model's base parameters (excitation/criterion.hpp), solved by Ipopt
// with the exact gradient, from several random starts.
//
// Constraints, at the N design instants of a period:
//   - at rest at `start` at t = 0 and so at the end of every period (2 linear equalities per
//     joint, q0 eliminated);
//   - joint position, velocity and acceleration limits (linear in the coefficients);
//   - torque limits of the nominal model (its phi), times `torque_margin`, and optional
//     workspace half-spaces on frame origins, each aggregated over the instants by a smooth,
//     conservative maximum (Kreisselmeier-Steinhauser: dense rows per instant made the
//     solver's factorization 10x slower).
// Then a dense check at `check_period` (the control period: the instants a controller steps
// through) holds every limit at 100 % over the whole period; a start that fails it is not
// chosen, and a design none of whose starts passes is refused, naming the constraint, joint
// and time.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/excitation/criterion.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/trajectory/fourier.hpp"

namespace symoro::excitation {

struct ExcitationLimits {
  Eigen::VectorXd lower, upper;            // joint positions the motion stays in (rad or m)
  Eigen::VectorXd velocity, acceleration;  // |qd|, |qdd| (> 0)
  Eigen::VectorXd torque;                  // |tau| of the nominal model; empty: not constrained
};

struct ExcitationDesignOptions {
  std::string name = "OF01";
  double period = 10;  // s, one period of the series
  int harmonics = 5;
  int samples = 0;        // design instants per period; 0: 20 per harmonic, at least 100
  Eigen::VectorXd start;  // the rest pose at the start and the end
  ExcitationLimits limits;
  Eigen::VectorXd nominal;      // phi of the nominal model (required with limits.torque)
  double torque_margin = 0.95;  // of the torque limit at the design instants
  std::vector<HalfSpace> workspace;
  double workspace_margin = 0.01;  // m inside the half-spaces at the design instants
  int starts = 4;
  // Starts solved at once, each in a forked process of its own (0: the cores; 1: one after the
  // other, in this process). The design is the same either way.
  int workers = 0;
  std::uint64_t seed = 1;
  int max_iterations = 150;    // per start
  double tolerance = 1e-5;     // Ipopt's relative tolerance
  double check_period = 1e-3;  // s
  // Joints (0-based) that hold `start` throughout: their coefficients are fixed at 0.
  std::vector<int> held;
  // The parameters the design is D-optimal for, when not the model's base parameters:
  // phi = parameter_map theta (ExcitationCriterion::set_parameter_map; empty: phi itself).
  Eigen::MatrixXd parameter_map;
};

// A limit the motion comes nearest to (or passes) in the dense check.
struct ExcitationSlack {
  std::string constraint;  // position, velocity, acceleration, torque, workspace
  std::string where;       // the joint's (or half-space's) name
  double slack = 0;        // limit minus |value|, in the constraint's unit; < 0: violated
  double time = 0;         // s
};

struct ExcitationStart {
  double criterion = 0;  // -f at the start's end (larger is better); -inf when it has none
  std::string status;    // Ipopt's return status
  int iterations = 0;
  double seconds = 0;
  bool solved = false;                       // Ipopt's status: a normal end (converged, acceptable, a limit reached)
  bool passed = false;                       // solved, and the dense check passed
  ExcitationSlack worst;                     // the tightest limit of the dense check
  trajectory::FourierTrajectory trajectory;  // the start's design, when it passed
};

struct ExcitationDesign {
  trajectory::FourierTrajectory trajectory;
  Eigen::VectorXd scales;  // S of the criterion (the first start's column norms)
  double criterion = 0;    // log det(S W'W S / N) at the design instants
  int chosen = -1;         // index into starts
  std::vector<ExcitationStart> starts;
  std::vector<ExcitationSlack> slack;  // per constraint kind, the tightest of the chosen design
  double seconds = 0;
};

// A design whose limits cannot be met (the message names the constraint and the joint).
struct ExcitationInfeasible : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws ExcitationInfeasible for a start outside the position limits or the workspace, a
// gravity torque at the start beyond the torque limit, a non-positive velocity or acceleration
// limit, or when no start passes the dense check; std::invalid_argument for sizes that do not
// match the model.
ExcitationDesign design_excitation(const identify::IdentificationModel& model, const ExcitationDesignOptions& options);

// The dense check of a series against the options' limits: the tightest slack per constraint
// kind (position, velocity, acceleration, then torque and workspace when constrained).
std::vector<ExcitationSlack> check_excitation(const identify::IdentificationModel& model,
                                              const trajectory::FourierTrajectory& t,
                                              const ExcitationDesignOptions& options);

}  // namespace symoro::excitation
