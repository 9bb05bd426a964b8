#include "symoro/codegen/effects.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "symoro/codegen/emitter.hpp"
#include "symoro/effect_table.hpp"

namespace symoro::codegen {

namespace {

// The variant effects in canonical order (EffectKind's, which orders the parameters they add),
// each a row of the effect table by its variant name. A row added to the table after these
// follows them, in the table's order.
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
    std::vector<const EffectRow*> rows;
    for (std::string_view name : kVariantOrder) rows.push_back(find_effect(&EffectRow::variant, name));
    for (const EffectRow& row : kEffectTable)
      if (!row.variant.empty() && std::find(rows.begin(), rows.end(), &row) == rows.end()) rows.push_back(&row);
    std::vector<Entry> out;
    for (const EffectRow* row : rows)
      out.push_back({static_cast<EffectKind>(out.size()), row, std::string(row->variant), effect_words(row->unfixes)});
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

bool effect_has_velocity(EffectKind kind) { return !entry(kind).row->velocity_scale.empty(); }

const EffectRow& effect_row(EffectKind kind) { return *entry(kind).row; }

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
    const double velocity = row.velocity_scale.empty() ? 0.0 : e->velocity;
    std::vector<int> orders = e->orders;
    std::sort(orders.begin(), orders.end());
    for (const EffectParameterName& p : effect_parameter_names(row, j, orders))
      out.push_back({p.name, p.family, j, u, p.order, velocity});
  }
  return out;
}

namespace {

// A joint law's nodes in the expression graph. |a| is a sign(a): the generated code has no abs.
class GraphLaw final : public LawAlgebra {
 public:
  explicit GraphLaw(ExprGraph& g) : g_(g) {}
  Value constant(double c) override { return g_.constant(c); }
  Value add(Value a, Value b) override { return g_.add(a, b); }
  Value sub(Value a, Value b) override { return g_.sub(a, b); }
  Value mul(Value a, Value b) override { return g_.mul(a, b); }
  Value div(Value a, Value b) override { return g_.div(a, b); }
  Value neg(Value a) override { return g_.neg(a); }
  Value square(Value a) override { return g_.pow(a, 2.0); }
  Value abs(Value a) override {
    const NodeId sign = g_.sign(a);
    return g_.mul(a, sign);
  }
  Value sign(Value a) override { return g_.sign(a); }
  Value exp(Value a) override { return g_.exp(a); }
  Value tanh(Value a) override { return g_.tanh(a); }
  Value sin(Value a) override { return g_.sin(a); }
  Value cos(Value a) override { return g_.cos(a); }

 private:
  ExprGraph& g_;
};

// A joint law as text for `symoroc info`, e.g. "sign(QP2)*exp(-(QP2/0.05)^2)": each value with
// the precedence of its outer operation, parenthesized where an operation binds tighter.
class TextLaw final : public LawAlgebra {
 public:
  enum Prec { kSum, kProduct, kUnary, kPower, kAtom };
  Value atom(std::string s) { return put(std::move(s), kAtom); }
  const std::string& text(Value v) const { return parts_.at(static_cast<std::size_t>(v)).s; }

  Value constant(double c) override {
    const bool integer = c == std::floor(c) && std::abs(c) < 1e15;
    return put(integer ? std::to_string(static_cast<long long>(c)) : cpp_literal(c), c < 0 ? kUnary : kAtom);
  }
  Value add(Value a, Value b) override { return put(wrap(a, kSum) + " + " + wrap(b, kSum), kSum); }
  Value sub(Value a, Value b) override { return put(wrap(a, kSum) + " - " + wrap(b, kProduct), kSum); }
  Value mul(Value a, Value b) override {
    if (text(a) == "1") return b;
    if (text(b) == "1") return a;
    return put(wrap(a, kProduct) + "*" + wrap(b, kPower), kProduct);
  }
  Value div(Value a, Value b) override { return put(wrap(a, kProduct) + "/" + wrap(b, kPower), kProduct); }
  Value neg(Value a) override { return put("-" + wrap(a, kPower), kUnary); }
  Value square(Value a) override { return put(wrap(a, kAtom) + "^2", kPower); }
  Value abs(Value a) override { return atom("|" + text(a) + "|"); }
  Value sign(Value a) override { return call("sign", a); }
  Value exp(Value a) override { return call("exp", a); }
  Value tanh(Value a) override { return call("tanh", a); }
  Value sin(Value a) override { return call("sin", a); }
  Value cos(Value a) override { return call("cos", a); }

 private:
  struct Part {
    std::string s;
    int prec;
  };
  Value put(std::string s, int prec) {
    parts_.push_back({std::move(s), prec});
    return static_cast<Value>(parts_.size() - 1);
  }
  std::string wrap(Value v, int min_prec) const {
    const Part& p = parts_.at(static_cast<std::size_t>(v));
    return p.prec >= min_prec ? p.s : "(" + p.s + ")";
  }
  Value call(const char* f, Value a) { return atom(std::string(f) + "(" + text(a) + ")"); }

  std::vector<Part> parts_;
};

// The row whose law gives the parameter's term, and the law's inputs but for q and qd.
FamilyLaw law_of(const EffectParameter& p) {
  const FamilyLaw law = family_law(p.family);
  if (!law.row) throw std::logic_error("no term for effect parameter family " + p.family);
  return law;
}

}  // namespace

NodeId effect_term(ExprGraph& g, const EffectParameter& p, NodeId q, NodeId qd) {
  const FamilyLaw law = law_of(p);
  GraphLaw a(g);
  return law.row->law(a, {q, qd, law.family, p.velocity, p.order});
}

std::string effect_term_text(const EffectParameter& p, const std::string& q, const std::string& qd) {
  const FamilyLaw law = law_of(p);
  TextLaw a;
  const LawAlgebra::Value vq = a.atom(q), vqd = a.atom(qd);
  return a.text(law.row->law(a, {vq, vqd, law.family, p.velocity, p.order}));
}

}  // namespace symoro::codegen
