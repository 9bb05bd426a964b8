// robot.yaml's checks of what yaml-cpp lets through: a key the reader does not know (a typo such
// as `lowr:` would otherwise be ignored) and a quoted value without its closing quote. The same
// checks as the runtime's symoro/io/yaml_keys.hpp, again here because the compiler links no
// runtime library; errors are InputError ("file:line:column: error: ...").
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace symoro::codegen {

// The YAML document in `path`: a syntax error (or an unclosed quote) is an InputError at its
// line and column, "YAML syntax error: ...".
YAML::Node load_yaml_file(const std::string& path);

// Refuses the first key of `map` not in `known`, or given twice, at the key:
// "unknown key 'lowr' in a joint; did you mean 'lower'? (known keys: ...)".
void check_keys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& file,
                const std::string& where);

// The name of `known` nearest to `name` by edits (insert, delete, substitute, swap neighbours),
// or "" when none is close enough to be a misspelling of it.
std::string nearest_name(const std::string& name, const std::vector<std::string>& known);

}  // namespace symoro::codegen
