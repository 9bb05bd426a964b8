// What urdfdom takes from a URDF without a word, checked where it is written: numbers that are
// NaN, infinite, text, empty or absurdly large (a NaN inertia became 0, a NaN mass dropped the
// whole inertial), inverted joint limits, and xacro macros left in the file.
#pragma once

#include <string>

class TiXmlDocument;

namespace symoro::codegen::modeling {

// Throws InputError naming the file, line, column, the link or joint, the attribute and the value.
void check_urdf_values(const TiXmlDocument& doc, const std::string& path);

}  // namespace symoro::codegen::modeling
