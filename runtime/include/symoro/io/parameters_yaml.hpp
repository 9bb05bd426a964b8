// An identification's accepted parameters read back from a study's report/parameters.yaml
// (study/report.hpp writes it): the controller's model feed-forward and the diagnosis of an
// earlier identification's gap (dynid control --params, dynid diagnose --params) use it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::io {

// The `parameters:` list as the identified model's phi, in `names` order; every name must be
// there and no other. Throws DataError with the file and line.
Eigen::VectorXd read_parameters_yaml(const std::string& path, const std::vector<std::string>& names);

// The file's `accepted:` flag: whether the identification's final all-pose audit passed. A file
// without it is not accepted. Throws DataError with the file and line on a flag that is not a
// boolean.
bool parameters_accepted(const std::string& path);

// The file's `torque_delay_ms:` in seconds: the shift of the logged torque the parameters were
// identified with (preprocess::Options::torque_delay). A fit on top of them (dynid payload, dynid
// predict) takes the same unless told otherwise: an arm's identification takes the logged
// torque's timing into its rotor inertias, and another timing shows as inertia (docs/payload.md).
// Empty for a file written before the key existed. Throws DataError with the file and line on a
// value that is not a number of ms within +-1000.
std::optional<double> parameters_torque_delay(const std::string& path);

// The digest identify writes under `digest:` (io/digest.hpp): of the robot, the model, the
// `accepted:` flag and every parameter's exact value, in `names` order. An edited value or flag
// no longer matches it.
std::string parameters_digest(const std::string& robot, const std::string& model, bool accepted,
                              const std::vector<std::string>& names, const Eigen::VectorXd& values);

// Whether the file is as identify wrote it: its digest is there and matches its content. `why`
// says what differs (no digest, or which digest against which).
struct ParametersIntegrity {
  bool intact = false;
  std::string why;
};
ParametersIntegrity parameters_integrity(const std::string& path, const std::vector<std::string>& names);

}  // namespace symoro::io
