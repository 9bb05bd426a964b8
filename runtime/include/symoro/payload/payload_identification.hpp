// A payload's (or tool's) 10 inertial parameters from logs of an arm carrying it, on top of the
// arm's identified model (dynid payload, symoro.identify_payload).
//
// The arm's parameters stay fixed: its torque ID(q, qd, qdd; phi) is taken from the measured
// torque, and what is left is the payload's, linear in its standard parameters theta on the
// last massive link (payload_inertial.hpp): tau - ID(phi) = W_full(q, qd, qdd) P theta + e, with
// W_full the robot's full model's regressor (products of inertia included, whatever variant the
// arm was identified with) and P the full model's base parameters per unit of that link's
// standard parameters. q, qd, qdd and tau come from the identification's own preprocessing
// (study/prediction.hpp), so the payload sees the samples the arm was identified on.
//
// Solved by weighted least squares (each joint's rows by the inverse of its residual's standard
// deviation, re-estimated), with a covariance that counts the residual's autocorrelation
// (Newey-West, Bartlett weights, the lag from the residual itself): the filtered samples are
// not independent, and a covariance that took them so would claim several times too much. When
// the estimate is not a body (mass <= 0 or a pseudo-inertia that is not positive definite) it
// is projected onto the nearest one in the estimate's own covariance metric (Ceres, J = U U'
// with U upper triangular). With a known mass, the mass is held and the other 9 identified.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "symoro/identify/identification_model.hpp"
#include "symoro/io/log.hpp"
#include "symoro/payload/payload_inertial.hpp"

namespace symoro::payload {

// Where a payload rides in a model: the last frame with a mass parameter (1-based) and the
// model's base parameters per unit of that link's standard parameters (np x 10, the order of
// payload_standard_names). Throws std::invalid_argument when the model has no such link.
struct PayloadLink {
  int link = 0;
  Eigen::MatrixXd map;
};
PayloadLink payload_link(const identify::IdentificationModel& model);

struct PayloadOptions {
  double interval = 0.010;     // s, the preprocessing's sampling interval
  double torque_delay = 0;     // s the logged torque lags the links'
  std::optional<double> mass;  // kg: the known-mass case (the other 9 parameters identified)
  // The flange frame F, in which the payload is given and reported, in the link's model frame L.
  Eigen::Isometry3d flange_in_link = Eigen::Isometry3d::Identity();
  int lags = -1;           // the covariance's lags; < 0: from the residual's autocorrelation
  int wls_iterations = 3;  // re-estimations of the joints' weights (0: unweighted)
  // Instrumental variables: the payload regressor of the logged reference motion (q_ref, qd_ref,
  // through the same preprocessing) instruments the measured one, theta = (Z'W X)^-1 Z'W y. The
  // measured positions carry the encoders' noise, to which a closed-loop controller's current
  // answers: least squares then takes the payload about 0.5 % light on the CRANE-X7 twin, and
  // its inertia about x and y 5-8 % low; the instruments do not share that noise (mass within
  // about 0.1 %, the inertia's error halved, at the same scatter: docs/payload.md). Needs logs
  // with reference columns.
  bool reference_instruments = false;
};

struct PayloadEstimate {
  PayloadInertial payload;  // in the flange frame
  // Standard deviations of the reported numbers (delta method over the covariance): mass, CoM,
  // and the inertia about the CoM as Ixx Iyy Izz Ixy Ixz Iyz; the mass's is 0 when it was given.
  double mass_std = 0;
  Eigen::Vector3d com_std = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 1> inertia_std = Eigen::Matrix<double, 6, 1>::Zero();
  StandardVector standard;       // the result, the link's standard parameters (link frame)
  StandardVector least_squares;  // the unconstrained estimate (= standard unless projected)
  Eigen::Matrix<double, kInertialParameters, kInertialParameters> covariance;  // of least_squares
  bool known_mass = false;
  bool instrumented = false;  // PayloadOptions::reference_instruments
  bool projected = false;     // the estimate was no body: standard is the nearest body
  double distance = 0;        // Mahalanobis distance of the projection (0 when none)
  double margin = 0;          // consistency_margin(standard) (> 0: a body)
  int link = 0;               // the model frame the payload rides on
  int samples = 0, lags = 0;
  double condition = 0;         // of the column-scaled weighted payload regressor
  Eigen::VectorXd weights;      // per joint, 1 / N m
  Eigen::VectorXd rms_without;  // N m per joint: tau - ID(phi), the arm alone
  Eigen::VectorXd rms_with;     // N m per joint: with the payload (and the tare's correction)
  std::string status;           // one sentence
  // With tare logs: the arm's own error along the payload's 10 parameters, which they measured
  // and which was taken out of the payload (zero without), and their sample count.
  StandardVector tare = StandardVector::Zero();
  int tare_samples = 0;
};

// `logs` of the arm carrying the payload; `arm` and `phi` the arm's identified model (its
// parameters are held), `full` the robot's full model (the payload's regressor). Throws
// DataError for logs the preprocessing refuses, std::invalid_argument when the logs do not
// excite the payload's parameters (the message names the weakest combination) or sizes differ.
PayloadEstimate identify_payload(const std::vector<io::Log>& logs, const identify::IdentificationModel& arm,
                                 const Eigen::VectorXd& phi, const identify::IdentificationModel& full,
                                 const PayloadOptions& options = {});

// The same with `tare` logs: the arm without the payload, best on the same motion. The payload
// is only as good as the arm's parameters of its link: an error there of a fraction of the
// payload's inertia about its CoM (a small difference of large second moments) goes straight
// into it. The tare logs measure that error, delta, along the payload's 10 parameters, and the
// fit takes it out: tau - ID(phi) = X (theta + delta) carrying, X delta without, solved together
// (theta's mass alone held when known). On the CRANE-X7 twin with the main study's arm:
// docs/payload.md.
PayloadEstimate identify_payload(const std::vector<io::Log>& logs, const std::vector<io::Log>& tare,
                                 const identify::IdentificationModel& arm, const Eigen::VectorXd& phi,
                                 const identify::IdentificationModel& full, const PayloadOptions& options = {});

}  // namespace symoro::payload
