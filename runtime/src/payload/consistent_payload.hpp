// The nearest body to a payload estimate that is none: min (theta - theta0)' C^-1 (theta - theta0)
// over theta whose pseudo-inertia is J = U U' (U upper triangular, so J >= 0 by construction and
// U(3, 3)^2 the mass), with Ceres. A known mass holds U(3, 3) = sqrt(mass).
#pragma once

#include <string>

#include <Eigen/Core>

#include "symoro/payload/payload_inertial.hpp"

namespace symoro::payload {

struct ConsistentPayload {
  StandardVector standard;
  double distance = 0;  // sqrt of the objective at the end
  std::string why;      // what made theta0 no body
};

// covariance: 10 x 10 (a known mass's row and column are 0 and not used).
ConsistentPayload nearest_body(const StandardVector& theta0, const Eigen::MatrixXd& covariance, bool known_mass);

}  // namespace symoro::payload
