// A robot folder's name names the generated namespace (symoro::<name>) and the robot library's
// symbols: it must be a C++ identifier that is no keyword and hides nothing the generated code
// names (std, Eigen, ceres, symoro, detail). `class`, `int` or `std` generated code that did not
// compile.
#pragma once

#include <string>

namespace symoro::codegen {

// "" when `name` can name a robot, else why not (a sentence naming it).
std::string robot_name_problem(const std::string& name);

}  // namespace symoro::codegen
