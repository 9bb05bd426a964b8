// Reading the YAML files people edit (dataset.yaml, import mappings, controller.yaml,
// hardware.yaml, twin.yaml, trajectory designs, log sidecars): a key the reader does not know is
// an error at its line, not ignored. A typo such as `windw:` for `window:` would otherwise drop
// the setting silently. A syntax error names its line and column.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace symoro::io {

// The YAML document in `path`. A syntax error is a DataError
// "path:line:column: error: YAML syntax error: ...", and so is a quoted value without its closing
// quote (yaml-cpp reads it as text running to the end of the file); an unreadable file is one
// at line 0.
YAML::Node load_yaml_file(const std::filesystem::path& path);
// The same for text already read; `file` names it in errors.
YAML::Node load_yaml_text(const std::string& text, const std::string& file);

// Refuses the first key of `map` that is not in `known`, or that appears twice, with a DataError
// at the key's line: "unknown key 'windw' in a run; did you mean 'window'? (known keys: ...)".
// `where` names the map in the message. Anything but a map is left to the reader.
void check_keys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& file,
                const std::string& where);

// The name of `known` nearest to `name` (by edits: insertions, deletions, substitutions and swaps
// of neighbours), or "" when none is close enough to be a misspelling of it.
std::string nearest_name(const std::string& name, const std::vector<std::string>& known);

}  // namespace symoro::io
