// Vectors in the identification's YAML files (run records, validation): one flow sequence.
#pragma once

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

namespace symoro::study::detail {

inline void put_vector(YAML::Emitter& y, const char* key, const Eigen::VectorXd& v) {
  y << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < v.size(); ++i) y << v(i);
  y << YAML::EndSeq;
}

}  // namespace symoro::study::detail
