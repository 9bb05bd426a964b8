// Numbers in the YAML files dynid writes and reads back (payload.yaml, uncertainty.yaml): a
// finite number, or a list of a given count, strictly parsed (io/number_text.hpp), a DataError
// at the node's line naming `what` otherwise ("what: not a finite number", "what: a list of 3
// numbers").
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Core>

namespace YAML {
class Node;
}

namespace symoro::io {

double yaml_number(const YAML::Node& node, const std::string& file, const std::string& what);
Eigen::VectorXd yaml_numbers(const YAML::Node& node, std::size_t count, const std::string& file,
                             const std::string& what);

}  // namespace symoro::io
