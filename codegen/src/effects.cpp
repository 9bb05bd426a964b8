#include "symoro/codegen/effects.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <tuple>

#include "symoro/codegen/emitter.hpp"
#include "symoro/effect_table.hpp"

namespace symoro::codegen {

namespace {

// The variant effects in canonical order (EffectKind's, which orders the parameters they add),
// each a row of the effect table by its variant name.
constexpr std::array<std::string_view, 7> kVariantOrder{
    "coulomb", "inertia_products", "offset", "stribeck", "viscous_asymmetry", "position_harmonics", "smooth_coulomb"};
static_assert(kVariantOrder.size() == static_cast<std::size_t>(EffectKind::SmoothCoulomb) + 1);

static_assert(every_name_has_a_row(&EffectRow::variant, kVariantOrder),
              "a variant effect without its row in symoro/effect_table.hpp");

struct Entry {
  EffectKind kind;
  const EffectRow* row;
  std::string name;
  std::vector<std::string> unfixes;
};

const std::vector<Entry>& catalogue() {
  static const std::vector<Entry> entries = [] {
    std::vector<Entry> out;
    for (std::size_t k = 0; k < kVariantOrder.size(); ++k) {
      const EffectRow* row = find_effect(&EffectRow::variant, kVariantOrder[k]);
      out.push_back({static_cast<EffectKind>(k), row, std::string(row->variant), effect_words(row->unfixes)});
    }
    return out;
  }();
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

bool effect_on_links(EffectKind kind) { return entry(kind).row->scope == EffectScope::Link; }

bool effect_has_velocity(EffectKind kind) { return entry(kind).row->velocity_scale; }

const std::vector<std::string>& unfixed_families(EffectKind kind) { return entry(kind).unfixes; }

std::vector<EffectParameter> effect_parameters(const std::vector<EffectSpec>& effects,
                                               const std::function<std::string(const std::string&, int)>& unit) {
  std::vector<const EffectSpec*> sorted;
  for (const auto& e : effects)
    if (unfixed_families(e.kind).empty()) sorted.push_back(&e);
  std::stable_sort(sorted.begin(), sorted.end(), [](const EffectSpec* a, const EffectSpec* b) {
    return std::make_tuple(static_cast<int>(a->kind), a->index) < std::make_tuple(static_cast<int>(b->kind), b->index);
  });
  std::vector<EffectParameter> out;
  for (const EffectSpec* e : sorted) {
    const EffectRow& row = *entry(e->kind).row;
    const int j = e->index;
    // The unit of the base family the row's parameters share (prismatic joints have their own).
    const std::string u = row.unit_like == EffectUnit::LikeFV   ? unit("FV", j)
                          : row.unit_like == EffectUnit::LikeFS ? unit("FS", j)
                                                                : std::string(row.unit);
    const double velocity = row.velocity_scale ? e->velocity : 0.0;
    std::vector<int> orders = e->orders;
    std::sort(orders.begin(), orders.end());
    for (const EffectParameterName& p : effect_parameter_names(row, j, orders))
      out.push_back({p.name, p.family, j, u, p.order, velocity});
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
