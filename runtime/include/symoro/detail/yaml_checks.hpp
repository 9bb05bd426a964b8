// What the runtime's YAML readers (io/yaml_keys.hpp) and the compiler's robot.yaml reader
// (codegen/src/yaml_check.hpp) check alike, header-only so that the compiler links no runtime
// library: a quoted value without its closing quote, unknown and repeated keys, the nearest
// known name. Each caller throws its own error type through `fail(line, column, message)`.
#pragma once

#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/anchor.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

namespace symoro::detail {

// Where the quoted scalar opening at text[at] ends (just past its closing quote), or npos when
// the text ends first. Inside "...", a backslash escapes the next character; inside '...', ''
// is a quote.
inline std::size_t quoted_end(const std::string& text, std::size_t at) {
  const char quote = text[at];
  for (std::size_t k = at + 1; k < text.size(); ++k) {
    if (quote == '"' && text[k] == '\\') {
      ++k;
    } else if (text[k] == quote) {
      if (quote == '\'' && k + 1 < text.size() && text[k + 1] == '\'') {
        ++k;
      } else {
        return k + 1;
      }
    }
  }
  return std::string::npos;
}

// yaml-cpp takes a quoted scalar without its closing quote for text running to the end of the
// file (the keys after it vanish into it): refused at the opening quote.
template <class Fail>
void check_quotes(const YAML::Node& n, const std::string& text, const Fail& fail) {
  if (n.IsScalar()) {
    const YAML::Mark m = n.Mark();
    if (m.is_null() || m.pos < 0 || static_cast<std::size_t>(m.pos) >= text.size()) return;
    const char c = text[static_cast<std::size_t>(m.pos)];
    if ((c == '"' || c == '\'') && quoted_end(text, static_cast<std::size_t>(m.pos)) == std::string::npos)
      fail(m.line + 1, m.column + 1,
           std::string("YAML syntax error: the quoted value opened here by ") + c + " has no closing quote");
  } else if (n.IsMap()) {
    for (const auto& e : n) {
      check_quotes(e.first, text, fail);
      check_quotes(e.second, text, fail);
    }
  } else if (n.IsSequence()) {
    for (const auto& e : n) check_quotes(e, text, fail);
  }
}

// Edits from a to b: insertions, deletions, substitutions and swaps of neighbours ("splti").
inline std::size_t edits(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// The name of `known` nearest to `name` (case ignored): at most 2 edits and at most half the
// longer name ("qq" may be "q", "x" is not "q"); of equally near names, one as long ("YM": "MY"
// rather than "M"). Empty when none is near.
inline std::string nearest_name(const std::string& name, const std::vector<std::string>& known) {
  const auto lower = [](std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  std::string best;
  std::pair<std::size_t, std::size_t> best_score;  // edits, then the difference in length
  for (const std::string& k : known) {
    const std::size_t e = edits(lower(name), lower(k));
    if (e > 2 || 2 * e > std::max(name.size(), k.size())) continue;
    const std::pair<std::size_t, std::size_t> score{e,
                                                    std::max(name.size(), k.size()) - std::min(name.size(), k.size())};
    if (best.empty() || score < best_score) best = k, best_score = score;
  }
  return best;
}

// Every key of `map` is one of `known`, once: else fail(line, column, message) with the nearest
// known key and the list. `where` names the map ("a run", "robot.yaml").
template <class Fail>
void check_keys(const YAML::Node& map, const std::vector<std::string>& known, const std::string& where,
                const Fail& fail) {
  if (!map.IsMap()) return;
  std::map<std::string, int> seen;  // key -> its line
  for (const auto& e : map) {
    const YAML::Mark m = e.first.Mark();
    const int line = m.is_null() ? 0 : m.line + 1, column = m.is_null() ? 0 : m.column + 1;
    if (!e.first.IsScalar()) fail(line, column, "a key of " + where + " must be a single word");
    const std::string key = e.first.Scalar();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      const std::string near = nearest_name(key, known);
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(line, column,
           "unknown key '" + key + "' in " + where + (near.empty() ? "" : "; did you mean '" + near + "'?") +
               " (known keys: " + list + ")");
    }
    const auto [at, fresh] = seen.emplace(key, line);
    if (!fresh)
      fail(line, column,
           "key '" + key + "' appears twice in " + where + " (first on line " + std::to_string(at->second) + ")");
  }
}

// What a YAML document may hold before any node is built, from the parser's events: one
// document (a second one, after '---', would be ignored), and aliases that neither name a node
// they sit inside (a cycle: `&s {<<: *s}` crashed every reader) nor expand the document past
// kMaxYamlNodes nodes (ten levels of ten aliases, the "billion laughs", ran for minutes). Anchors
// themselves are fine (twin.yaml names its servo models with them). A syntax error is left to
// the loader, which reports it.
inline constexpr long long kMaxYamlNodes = 1'000'000;

template <class Fail>
void check_yaml_structure(const std::string& text, const Fail& fail) {
  struct Events : YAML::EventHandler {
    explicit Events(const Fail& f) : fail(f) {}
    const Fail& fail;
    int documents = 0;
    long long nodes = 0;                                     // after expanding the aliases so far
    std::vector<std::pair<YAML::anchor_t, long long>> open;  // anchored containers being read
    std::map<YAML::anchor_t, long long> size;                // each anchored node's expanded size
    void node(const YAML::Mark& mark, long long count) {
      nodes += count;
      if (nodes > kMaxYamlNodes)
        fail(mark.line + 1, mark.column + 1,
             "YAML aliases expand this document past " + std::to_string(kMaxYamlNodes) + " nodes: refused");
    }
    void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
      node(mark, 1);
      if (anchor != YAML::NullAnchor) size[anchor] = 1;
    }
    void start(const YAML::Mark& mark, YAML::anchor_t anchor) {
      node(mark, 1);
      open.emplace_back(anchor, nodes - 1);
    }
    void end() {
      if (open.empty()) return;
      const auto [anchor, first] = open.back();
      open.pop_back();
      if (anchor != YAML::NullAnchor) size[anchor] = nodes - first;
    }
    void OnDocumentStart(const YAML::Mark& mark) override {
      if (++documents > 1)
        fail(mark.line + 1, mark.column + 1, "a second YAML document ('---'): one document per file");
    }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
    void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
      for (const auto& o : open)
        if (o.first == anchor)
          fail(mark.line + 1, mark.column + 1,
               "a YAML alias inside the node its anchor names: a cycle no reader can follow");
      const auto it = size.find(anchor);
      node(mark, it == size.end() ? 1 : it->second);
    }
    void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, const std::string&) override {
      leaf(mark, anchor);
    }
    void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                         YAML::EmitterStyle::value) override {
      start(mark, anchor);
    }
    void OnSequenceEnd() override { end(); }
    void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                    YAML::EmitterStyle::value) override {
      start(mark, anchor);
    }
    void OnMapEnd() override { end(); }
  };
  std::istringstream in(text);
  YAML::Parser parser(in);
  Events events(fail);
  try {
    while (parser.HandleNextDocument(events)) {
    }
  } catch (const YAML::ParserException&) {
    // the loader reports it
  }
}

}  // namespace symoro::detail
