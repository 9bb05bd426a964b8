// Whole-robot generation: the headers of the full model and of every variant, as text. The
// output depends only on the robot folder's contents, so it is reproducible and diffable.
#pragma once

#include <string>
#include <vector>

#include "symoro/codegen/passes.hpp"
#include "symoro/codegen/robot_model.hpp"

namespace symoro::codegen {

struct GeneratedFile {
  std::string path;  // relative to the output root, e.g. "crane_x7/include/symoro/crane_x7/model.hpp"
  std::string content;
};

// What `symoroc info` reports per generated model.
struct FunctionSummary {
  std::string name;
  OperationCount ops;
};
struct ModelSummary {
  std::string name;  // "crane_x7" or "crane_x7::reduced"
  std::string description;
  std::vector<ParameterRef> identified;  // base parameters, then effect parameters
  std::vector<std::pair<std::string, double>> fixed;
  std::vector<std::pair<std::string, std::string>> effects;  // effect parameter, the term it multiplies
  std::vector<FunctionSummary> functions;
};

struct Generation {
  std::vector<GeneratedFile> files;
  std::vector<ModelSummary> models;
};

Generation generate_robot(RobotModel& robot);

}  // namespace symoro::codegen
