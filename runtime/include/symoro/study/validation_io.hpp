// A study's held-out validation on disk, so that studies of different model variants can be
// compared later without recompiling either (dynid compare): <study>/validation.yaml (the
// model, the accepted parameters and each trajectory's errors) and one CSV of torque series
// per trajectory, <study>/validation/<TRAJ>.csv (time, then per joint the measured motion q, qd,
// qdd and the measured, CLIE and accepted torques). Written atomically; read back with errors naming the file and line.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/study/result.hpp"

namespace symoro::study {

struct StudyValidation {
  std::string robot, model;  // model: the variant's name ("" for the full model)
  std::string selected_run;  // e.g. "AG02@10ms"
  bool accepted = false;     // final all-pose audit passed
  bool rescued = false;
  std::vector<std::string> names, units;  // accepted parameters
  Eigen::VectorXd phi;                    // accepted parameters (rescue, or CLIE when PD)
  Eigen::VectorXd truth;                  // the twin's, when known (else empty)
  std::vector<ValidationRecord> records;  // with their series
};

// Writes <study>/validation.yaml and <study>/validation/<TRAJ>.csv; returns the files written.
// Nothing is written when the study has no validation records.
std::vector<std::filesystem::path> write_validation(const StudyResult& study, const std::filesystem::path& study_dir);

// Reads what write_validation wrote; throws DataError (file, line, problem) on anything missing
// or malformed.
StudyValidation read_validation(const std::filesystem::path& study_dir);

}  // namespace symoro::study
