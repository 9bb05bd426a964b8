// What a Log must satisfy to be written (and what read_log guarantees of what it returns).
#include <cmath>
#include <set>
#include <string>

#include <fmt/format.h>

#include "log_columns.hpp"
#include "symoro/error.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/number_text.hpp"

namespace symoro::io {

using detail::Group;

namespace {

void check_metadata(const LogMetadata& meta, const std::string& file) {
  if (!detail::is_known_source(meta.source))
    throw DataError(file, 0, fmt::format("unknown source '{}' (expected twin, robot or reference)", meta.source));
  if (meta.robot.empty()) throw DataError(file, 0, "the robot name is empty");
  if (meta.trial < 0) throw DataError(file, 0, fmt::format("trial {} is negative", meta.trial));
  if (!std::isfinite(meta.sample_time) || meta.sample_time <= 0)
    throw DataError(file, 0,
                    fmt::format("sample_time {} is not a positive finite number", number_text(meta.sample_time)));
  if (meta.joints.empty()) throw DataError(file, 0, "the joint list is empty");
  std::set<std::string> seen;
  for (std::size_t j = 0; j < meta.joints.size(); ++j) {
    if (meta.joints[j].empty()) throw DataError(file, 0, fmt::format("joint {} has an empty name", j + 1));
    if (!seen.insert(meta.joints[j]).second)
      throw DataError(file, 0, fmt::format("joint name '{}' appears twice", meta.joints[j]));
  }
}

void check_finite(const Eigen::MatrixXd& m, std::string_view group, const std::string& file) {
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index k = 0; k < m.rows(); ++k)
      if (!std::isfinite(m(k, j)))
        throw DataError(
            file, 0,
            fmt::format("{}{} at sample {} is {}, not a finite number", group, j + 1, k + 1, number_text(m(k, j))));
}

}  // namespace

void validate_log(const Log& log, const std::string& file) {
  const LogMetadata& meta = log.meta;
  check_metadata(meta, file);
  const Eigen::Index samples = log.time.size();
  const Eigen::Index joints = static_cast<Eigen::Index>(meta.joints.size());
  // A run that stopped before its first row (dynid control) leaves a valid, empty log whose
  // notes say why: the message carries them.
  if (samples == 0)
    throw DataError(file, 0,
                    meta.notes.empty() ? std::string("the log has no samples")
                                       : "the log has no samples; its notes: " + meta.notes);

  const bool reference = meta.source == detail::reference_source;
  for (Group g : detail::measured_groups) {
    const Eigen::MatrixXd& m = detail::group_matrix(log, g);
    if (reference && m.cols() != 0)
      throw DataError(file, 0,
                      fmt::format("a reference log has no {} columns, but {} has {}", detail::group_name(g),
                                  detail::group_name(g), m.cols()));
  }
  const int reference_groups_present =
      static_cast<int>(log.q_ref.cols() > 0) + (log.qd_ref.cols() > 0) + (log.qdd_ref.cols() > 0);
  if (reference_groups_present != 0 && reference_groups_present != 3)
    throw DataError(file, 0, "q_ref, qd_ref and qdd_ref must be all present or all empty");
  if (reference && reference_groups_present == 0)
    throw DataError(file, 0, "a reference log needs q_ref, qd_ref and qdd_ref");

  for (Group g : detail::groups_of(log)) {
    if (g == Group::time) continue;
    const Eigen::MatrixXd& m = detail::group_matrix(log, g);
    if (m.rows() != samples || m.cols() != joints)
      throw DataError(file, 0,
                      fmt::format("{} is {} x {} but the log has {} samples of {} joints (meta.joints)",
                                  detail::group_name(g), m.rows(), m.cols(), samples, joints));
    check_finite(m, detail::group_name(g), file);
  }

  for (Eigen::Index k = 0; k < samples; ++k) {
    if (!std::isfinite(log.time[k]))
      throw DataError(file, 0,
                      fmt::format("time at sample {} is {}, not a finite number", k + 1, number_text(log.time[k])));
    if (k > 0 && !(log.time[k] > log.time[k - 1]))
      throw DataError(file, 0,
                      fmt::format("time does not increase strictly: sample {} is at {} s, sample {} at {} s", k,
                                  number_text(log.time[k - 1]), k + 1, number_text(log.time[k])));
  }
}

}  // namespace symoro::io
