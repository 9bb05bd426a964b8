// A robot.yaml variant in terms of the robot's model: the base parameters it fixes (its patterns
// resolved, and what its effects fix or un-fix) and the effect parameters it adds, each checked
// against the model's names.
#include <algorithm>
#include <map>
#include <set>

#include "symoro/effect_table.hpp"
#include "variant_parameters.hpp"

namespace symoro::codegen::generate {

// Resolves a variant's patterns to base parameters; every pattern must match something. The
// base parameters its effects un-fix (coulomb, inertia_products) stay identified; those an
// effect's term replaces are fixed to 0 (smooth_coulomb's tanh replaces the files' FS sign).
std::vector<std::pair<std::string, double>> resolve_fixed(const RobotModel& r, const VariantSpec& v) {
  std::map<std::string, double> fixed;
  for (const auto& [pattern, value] : v.fixed) {
    bool matched = false;
    for (const auto& p : r.base) {
      if (!glob_match(pattern, p.name)) continue;
      matched = true;
      auto [it, inserted] = fixed.emplace(p.name, value);
      if (!inserted && it->second != value)
        throw InputError(r.spec.path, v.line, 1, "variant " + v.name + ": " + p.name + " is fixed to two values");
    }
    if (!matched)
      throw InputError(r.spec.path, v.line, 1, "variant " + v.name + ": '" + pattern + "' matches no base parameter");
  }
  // An effect whose term replaces base families on its joint (the effect table's `replaces`)
  // fixes them to 0, and cannot share the joint with an effect that un-fixes or replaces them.
  for (const auto& e : v.effects) {
    const EffectRow& row = effect_row(e.kind);
    const std::vector<std::string> replaced = effect_words(row.replaces);
    if (replaced.empty()) continue;
    for (const auto& other : v.effects) {
      if (&other == &e || other.index != e.index) continue;
      std::vector<std::string> theirs = unfixed_families(other.kind);
      for (const std::string& f : effect_words(effect_row(other.kind).replaces)) theirs.push_back(f);
      for (const std::string& f : replaced)
        if (std::find(theirs.begin(), theirs.end(), f) != theirs.end())
          throw InputError(r.spec.path, e.line, e.column,
                           "variant " + v.name + ": joint " + std::to_string(e.index) + " has both " +
                               effect_name(std::min(e.kind, other.kind)) + " and " +
                               effect_name(std::max(e.kind, other.kind)) + " (one " + std::string(row.title) +
                               " term per joint)");
    }
    for (const auto& p : r.base)
      if (p.joint == e.index && std::find(replaced.begin(), replaced.end(), p.family) != replaced.end())
        fixed[p.name] = 0.0;
  }
  for (const auto& e : v.effects) {
    const auto& families = unfixed_families(e.kind);
    if (families.empty()) continue;
    bool found = false;
    for (const auto& p : r.base)
      if (p.joint == e.index && std::find(families.begin(), families.end(), p.family) != families.end()) {
        found = true;
        fixed.erase(p.name);
      }
    if (!found) {
      std::string list;
      for (const auto& f : families) list += (list.empty() ? "" : ", ") + f + std::to_string(e.index);
      throw InputError(r.spec.path, e.line, e.column,
                       "variant " + v.name + ": effect " + effect_name(e.kind) + " on " +
                           (effect_on_links(e.kind) ? "link " : "joint ") + std::to_string(e.index) +
                           ": the model has no such base parameter (" + list + ")");
    }
  }
  std::vector<std::pair<std::string, double>> out;
  for (const auto& p : r.base)  // in parameter order
    if (auto it = fixed.find(p.name); it != fixed.end()) out.emplace_back(p.name, it->second);
  return out;
}

// The parameters a variant's effects add; their names must be new symbols.
std::vector<EffectParameter> resolve_effects(const RobotModel& r, const VariantSpec& v) {
  auto unit = [&](const std::string& family, int joint) {
    return r.frames[joint - 1].sigma == 1 ? r.spec.prismatic_units.at(family) : r.spec.units.at(family);
  };
  std::vector<EffectParameter> out = effect_parameters(v.effects, unit);
  std::set<std::string> taken;
  for (const auto& p : r.base) taken.insert(p.name);
  for (const auto& p : r.standard) taken.insert(p.name);
  for (const auto& c : r.spec.constants) taken.insert(c.first);
  for (const auto* list : {&r.q, &r.qd, &r.qdd, &r.tau}) taken.insert(list->begin(), list->end());
  for (const auto& p : out)
    if (taken.count(p.name))
      throw InputError(r.spec.path, v.line, 1,
                       "variant " + v.name + ": the effect parameter " + p.name + " is already a name of the model");
  return out;
}

}  // namespace symoro::codegen::generate
