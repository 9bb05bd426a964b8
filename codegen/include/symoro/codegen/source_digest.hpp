// The digests of a robot folder's files, generated as <robot>/source.hpp: the compiled model
// knows what it was compiled from, and dynid refuses a folder whose robot.yaml or model files
// differ (the compiled copy would be used silently). XXH3-128 as the runtime's io/digest.hpp.
#pragma once

#include <string>

#include "symoro/codegen/robot_model.hpp"

namespace symoro::codegen {

// The digest of a file's bytes (32 hex digits); throws InputError when it cannot be read.
std::string file_content_digest(const std::string& path);

// source.hpp: namespace symoro::<robot>::source { files[] = {{name, digest}, ...} }.
std::string source_digest_header(const RobotModel& r);

}  // namespace symoro::codegen
