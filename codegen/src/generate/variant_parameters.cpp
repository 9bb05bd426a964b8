// A robot.yaml variant in terms of the robot's model: the base parameters it fixes (its patterns
// resolved, and what its effects fix or un-fix) and the effect parameters it adds, each checked
// against the model's names.
#include <algorithm>
#include <map>
#include <set>

#include "variant_parameters.hpp"

namespace symoro::codegen::generate {

// Resolves a variant's patterns to base parameters; every pattern must match something. The
// base parameters its effects un-fix (coulomb, inertia_products) stay identified; smooth_coulomb
// fixes its joint's FS to 0 (its tanh term replaces the files' sign term).
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
  for (const auto& e : v.effects) {
    if (e.kind != EffectKind::SmoothCoulomb) continue;
    for (const auto& other : v.effects)
      if (other.kind == EffectKind::Coulomb && other.index == e.index)
        throw InputError(r.spec.path, e.line, e.column,
                         "variant " + v.name + ": joint " + std::to_string(e.index) +
                             " has both coulomb and smooth_coulomb (one Coulomb friction term per joint)");
    for (const auto& p : r.base)
      if (p.joint == e.index && p.family == "FS") fixed[p.name] = 0.0;
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
