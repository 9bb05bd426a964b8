#include "dynid_excite_payload.hpp"

#include <algorithm>
#include <limits>

#include <Eigen/SVD>
#include <fmt/format.h>

#include "dynid_common.hpp"
#include "symoro/payload/payload_identification.hpp"

namespace symoro::dynid {

PayloadExcitation payload_excitation(const identify::IdentificationModel& full, int wrist) {
  const identify::ModelDescription& d = full.description();
  PayloadExcitation p;
  const payload::PayloadLink link = payload::payload_link(full);
  p.map = link.map;
  p.link = link.link;
  // Movable frames in order carry q; the wrist is the last `wrist` of those up to the link.
  std::vector<int> upto;
  for (int f = 0, k = 0; f < static_cast<int>(d.frames.size()); ++f)
    if (d.frames[static_cast<std::size_t>(f)].sigma != 2) {
      if (f + 1 <= link.link) upto.push_back(k);
      ++k;
    }
  if (static_cast<int>(upto.size()) < wrist)
    throw UsageError(fmt::format("--payload-joints {}: the payload's link {} has {} joints before it", wrist, link.link,
                                 upto.size()));
  p.moving.assign(upto.end() - wrist, upto.end());
  for (int j = 0; j < d.nq; ++j)
    if (std::find(p.moving.begin(), p.moving.end(), j) == p.moving.end()) p.held.push_back(j);
  return p;
}

PayloadExcitation payload_setup(const identify::IdentificationModel& full, const std::string& model, int wrist,
                                double& period, int& harmonics, bool harmonics_given, int& periods,
                                bool periods_given) {
  if (!model.empty() && model != "full")
    throw UsageError("--payload designs on the full model (the payload's regressor): leave --model out");
  PayloadExcitation p = payload_excitation(full, wrist);
  if (period == 0) period = 8.5;
  if (!harmonics_given) harmonics = 12;  // up to 1.4 Hz: the inertia about the CoM needs acceleration
  if (!periods_given) periods = 2;
  std::string moving;
  for (const int j : p.moving)
    moving += std::string(moving.empty() ? "" : ", ") + full.description().joints[static_cast<std::size_t>(j)].name;
  fmt::print(
      "payload excitation: {} move, the other joints hold the posture; D-optimal for the 10 inertial parameters on "
      "link {}\n",
      moving, p.link);
  return p;
}

void wrist_limits(const PayloadExcitation& p, const identify::ModelDescription& d, Eigen::VectorXd& velocity,
                  Eigen::VectorXd& acceleration) {
  for (const int j : p.moving) {
    velocity(j) = 0.8 * d.joints[static_cast<std::size_t>(j)].velocity;
    acceleration(j) = 10 * velocity(j);
  }
}

std::string payload_quality(const identify::IdentificationModel& full, const PayloadExcitation& p,
                            const trajectory::Trajectory& t, const TrajectoryOptions& options) {
  const Eigen::MatrixXd X = trajectory_regressor(full, t, options) * p.map;
  const Eigen::VectorXd norms = X.colwise().norm();
  Eigen::MatrixXd Xs = X;
  for (Eigen::Index c = 0; c < X.cols(); ++c)
    if (norms(c) > 0) Xs.col(c) /= norms(c);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Xs);
  const Eigen::VectorXd sv = svd.singularValues();
  const double kappa = sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : std::numeric_limits<double>::infinity();
  const double per_sample = log_det_per_sample(RegressorFactor::of(X), full.description().nq);
  return fmt::format(
      "{}: {:.1f} s; payload (10 parameters on link {}): scaled kappa {:.4g}, log det per sample {:.4g}\n", t.name,
      t.duration(), p.link, kappa, per_sample);
}

}  // namespace symoro::dynid
