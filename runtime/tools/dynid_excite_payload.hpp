// dynid excite --payload: a short wrist motion D-optimal for a payload's 10 inertial parameters
// (payload/payload_identification.hpp), the arm's other joints holding their posture. What the
// excite command needs beyond its optimized series: which joints move, the parameter map, and
// the motion's payload quality (docs/payload.md).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid_trajectories.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::dynid {

struct PayloadExcitation {
  Eigen::MatrixXd map;      // the full model's base parameters per unit of the payload's 10
  std::vector<int> held;    // 0-based joints that hold the posture
  std::vector<int> moving;  // the `wrist` joints up to the payload's link
  int link = 0;
};

// The wrist: the last `wrist` movable joints at or before the payload's link. UsageError when
// the model has fewer.
PayloadExcitation payload_excitation(const identify::IdentificationModel& full, int wrist);

// --payload's setup: the wrist, and the series' shape unless given (20 s: two periods of 8.5 s,
// 12 harmonics, and the design's 3 s of holds); printed. UsageError for a --model other than full
// (the payload's regressor is the full model's).
PayloadExcitation payload_setup(const identify::IdentificationModel& full, const std::string& model, int wrist,
                                double& period, int& harmonics, bool harmonics_given, int& periods, bool periods_given);

// The wrist's limits (a payload's inertia about its CoM needs acceleration): 80 % of each moving
// joint's velocity limit, and 10/s times that; the torque limits bound the rest.
void wrist_limits(const PayloadExcitation& p, const identify::ModelDescription& d, Eigen::VectorXd& velocity,
                  Eigen::VectorXd& acceleration);

// The payload's excitation quality of a designed motion: its scaled condition number and log det
// per sample of the payload regressor W P, as a line of quality.txt.
std::string payload_quality(const identify::IdentificationModel& full, const PayloadExcitation& p,
                            const trajectory::Trajectory& t, const TrajectoryOptions& options);

}  // namespace symoro::dynid
