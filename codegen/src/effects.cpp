#include "symoro/codegen/effects.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>

#include "symoro/codegen/emitter.hpp"

namespace symoro::codegen {

namespace {

struct Entry {
  EffectKind kind;
  std::string name;
  std::vector<std::string> unfixes;
};

const std::vector<Entry>& catalogue() {
  static const std::vector<Entry> entries = {
      {EffectKind::Coulomb, "coulomb", {"FS"}},
      {EffectKind::InertiaProducts, "inertia_products", {"XY", "XZ", "YZ"}},
      {EffectKind::Offset, "offset", {}},
      {EffectKind::Stribeck, "stribeck", {}},
      {EffectKind::ViscousAsymmetry, "viscous_asymmetry", {}},
      {EffectKind::PositionHarmonics, "position_harmonics", {}},
      {EffectKind::SmoothCoulomb, "smooth_coulomb", {}},
  };
  return entries;
}

const Entry& entry(EffectKind kind) { return catalogue().at(static_cast<std::size_t>(kind)); }

}  // namespace

const std::string& effect_name(EffectKind kind) { return entry(kind).name; }

std::optional<EffectKind> effect_kind(const std::string& name) {
  for (const auto& e : catalogue())
    if (e.name == name) return e.kind;
  return std::nullopt;
}

std::string effect_names() {
  std::string out;
  for (const auto& e : catalogue()) out += (out.empty() ? "" : ", ") + e.name;
  return out;
}

bool effect_on_links(EffectKind kind) { return kind == EffectKind::InertiaProducts; }

bool effect_has_velocity(EffectKind kind) { return kind == EffectKind::Stribeck || kind == EffectKind::SmoothCoulomb; }

const std::vector<std::string>& unfixed_families(EffectKind kind) { return entry(kind).unfixes; }

std::vector<EffectParameter> effect_parameters(
    const std::vector<EffectSpec>& effects, const std::function<std::string(const std::string&, int)>& unit) {
  std::vector<const EffectSpec*> sorted;
  for (const auto& e : effects)
    if (unfixed_families(e.kind).empty()) sorted.push_back(&e);
  std::stable_sort(sorted.begin(), sorted.end(), [](const EffectSpec* a, const EffectSpec* b) {
    return std::make_tuple(static_cast<int>(a->kind), a->index) < std::make_tuple(static_cast<int>(b->kind), b->index);
  });
  std::vector<EffectParameter> out;
  for (const EffectSpec* e : sorted) {
    const int j = e->index;
    const std::string js = std::to_string(j);
    switch (e->kind) {
      case EffectKind::Offset: out.push_back({"OFF" + js, "OFF", j, unit("FS", j), 0, 0.0}); break;
      case EffectKind::Stribeck: out.push_back({"FST" + js, "FST", j, unit("FS", j), 0, e->velocity}); break;
      case EffectKind::ViscousAsymmetry: out.push_back({"FVA" + js, "FVA", j, unit("FV", j), 0, 0.0}); break;
      case EffectKind::SmoothCoulomb: out.push_back({"FC" + js, "FC", j, unit("FS", j), 0, e->velocity}); break;
      case EffectKind::PositionHarmonics: {
        std::vector<int> orders = e->orders;
        std::sort(orders.begin(), orders.end());
        for (int k : orders) {
          const std::string suffix = js + "_" + std::to_string(k);
          out.push_back({"HS" + suffix, "HS", j, unit("FS", j), k, 0.0});
          out.push_back({"HC" + suffix, "HC", j, unit("FS", j), k, 0.0});
        }
        break;
      }
      case EffectKind::Coulomb:
      case EffectKind::InertiaProducts: break;
    }
  }
  return out;
}

// Nodes are made one statement at a time: the order of evaluation of a call's arguments is
// unspecified, and node ids (hence the emitted text) must not depend on the compiler.
NodeId effect_term(ExprGraph& g, const EffectParameter& p, NodeId q, NodeId qd) {
  if (p.family == "OFF") return g.one();
  if (p.family == "FST") {  // sign(qd) exp(-(qd / v)^2)
    const NodeId sign = g.sign(qd);
    const NodeId exp = g.exp(g.neg(g.pow(g.div(qd, g.constant(p.velocity)), 2.0)));
    return g.mul(sign, exp);
  }
  if (p.family == "FVA") {  // |qd|
    const NodeId sign = g.sign(qd);
    return g.mul(qd, sign);
  }
  if (p.family == "FC") return g.tanh(g.div(qd, g.constant(p.velocity)));
  if (p.family == "HS") return g.sin(g.mul(g.constant(p.order), q));
  if (p.family == "HC") return g.cos(g.mul(g.constant(p.order), q));
  throw std::logic_error("no term for effect parameter family " + p.family);
}

std::string effect_term_text(const EffectParameter& p, const std::string& q, const std::string& qd) {
  const std::string kq = p.order == 1 ? q : std::to_string(p.order) + "*" + q;
  if (p.family == "OFF") return "1";
  if (p.family == "FST") return "sign(" + qd + ")*exp(-(" + qd + "/" + cpp_literal(p.velocity) + ")^2)";
  if (p.family == "FVA") return "|" + qd + "|";
  if (p.family == "FC") return "tanh(" + qd + "/" + cpp_literal(p.velocity) + ")";
  if (p.family == "HS") return "sin(" + kq + ")";
  if (p.family == "HC") return "cos(" + kq + ")";
  throw std::logic_error("no term for effect parameter family " + p.family);
}

}  // namespace symoro::codegen
