// The one table of model-gap effects: what the diagnosis looks for, what a robot.yaml variant
// compiles (`effects:`), and what the twin simulates, one row per physical effect with its name
// in each of the three. The diagnosis (diagnose/effects.cpp), the compiler (codegen/src/effects.cpp)
// and the twin's configuration (twin/config.cpp) take their names, titles, parameter families,
// units, physical checks and joint laws from here; tests/runtime/test_diagnose_effects.cpp checks,
// row by row, that the three evaluate the same term. Header-only, with no other header of the
// project than effect_law.hpp: symoroc reads it without linking the runtime.
//
// Adding a friction model (any term of a joint's q and qd): its law in effect_laws and its row in
// kEffectTable, both here. The diagnosis then looks for it on every joint, a robot.yaml variant
// compiles it, `symoroc info` prints it; see docs/architecture.md, "Where to add an effect".
#pragma once

#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "symoro/effect_law.hpp"

namespace symoro {

// What one instance of an effect acts on.
enum class EffectScope { Joint, Link, Robot };

// The unit of an effect's parameters, by the base family whose unit it shares on a revolute or a
// prismatic joint (robot.yaml parameter_units); Own: the row's `unit` whatever the joint.
enum class EffectUnit { LikeFS, LikeFV, LikeXY, Own };

struct EffectRow {
  std::string_view title;      // "Coulomb friction", in the diagnosis's labels
  std::string_view diagnosis;  // the diagnosis's name (dynid diagnose --only, reports, keys); "" when not diagnosed
  std::string_view variant;    // the robot.yaml variant effect it compiles to; "" when it is no model term
  std::string_view twin;       // the twin.yaml effect that simulates it; "" when the twin has none
  EffectScope scope;
  std::string_view families;  // the parameters' families, space separated ("HS HC": per order)
  EffectUnit unit_like;
  std::string_view unit;     // of the parameters on a revolute joint (with unit_like Own: always)
  std::string_view unfixes;  // base families a variant un-fixes instead of adding parameters ("FS")
  // Base families its term replaces on its joint: a variant fixes them to 0 and refuses an
  // effect that un-fixes them on the same joint (smooth Coulomb friction replaces FS sign(qd)).
  std::string_view replaces;
  // What its velocity scale is called, when a variant gives it {joints: [...], velocity: v}
  // ("the Stribeck velocity"); "" for none. default_velocity: v when robot.yaml gives none.
  std::string_view velocity_scale;
  double default_velocity;
  // Physical only with a positive first parameter (a friction level, a play, a mass, a delay):
  // a fit that makes it negative is absorbing another misfit.
  bool positive;
  std::string_view term;  // the torque on its joint's row, per parameter, in words
  // The term as a law of (q, qd) (symoro/effect_law.hpp): what the compiler compiles and the
  // diagnosis fits. Null for an effect that is no function of its joint's q and qd alone.
  JointLaw law;
};

// Each joint law (symoro/effect_law.hpp): the term its parameter multiplies on its joint's row.
namespace effect_laws {
using V = LawAlgebra::Value;
// FC tanh(qd / v): Coulomb friction smoothed over a velocity scale v.
inline V smooth_coulomb(LawAlgebra& a, const LawInputs& x) { return a.tanh(a.div(x.qd, a.constant(x.velocity))); }
// FST sign(qd) exp(-(qd / vs)^2): friction above Coulomb's at rest, fading with speed.
inline V stribeck(LawAlgebra& a, const LawInputs& x) {
  const V sign = a.sign(x.qd);
  const V fade = a.exp(a.neg(a.square(a.div(x.qd, a.constant(x.velocity)))));
  return a.mul(sign, fade);
}
// OFF: a constant torque.
inline V offset(LawAlgebra& a, const LawInputs&) { return a.constant(1.0); }
// FVA |qd|: viscous friction FV + FVA forward, FV - FVA backward.
inline V viscous_asymmetry(LawAlgebra& a, const LawInputs& x) { return a.abs(x.qd); }
// HS_k sin(k q), HC_k cos(k q): torque that repeats with the joint's position.
inline V position_harmonic(LawAlgebra& a, const LawInputs& x) {
  const V kq = a.mul(a.constant(x.order), x.q);
  return x.family == 0 ? a.sin(kq) : a.cos(kq);
}
// FSE sign(qd) exp(-|qd| / vs): Tustin's Stribeck friction, fading exponentially with speed.
inline V tustin_stribeck(LawAlgebra& a, const LawInputs& x) {
  const V sign = a.sign(x.qd);
  const V fade = a.exp(a.neg(a.div(a.abs(x.qd), a.constant(x.velocity))));
  return a.mul(sign, fade);
}
}  // namespace effect_laws

// The rows, in the twin's order of effects first (its names() and log notes keep that order).
// Each row: title; its names in the diagnosis, a variant, the twin; scope; parameter families,
// their unit (like a base family's, or its own); the base families a variant un-fixes and those
// its term replaces; the name of its velocity scale and its default; the physical check; the
// term in words; the joint law.
inline constexpr std::array<EffectRow, 16> kEffectTable{{
    {"Coulomb friction", "coulomb", "smooth_coulomb", "coulomb",  //
     EffectScope::Joint, "FC", EffectUnit::LikeFS, "N*m", "", "FS", "the velocity scale of tanh(qd/v)", 0.03, true,
     "FC tanh(qd / v); the diagnosis: the sign averaged over a velocity spread s (erf), v = s sqrt(pi / 2)",
     effect_laws::smooth_coulomb},
    {"Stribeck friction", "stribeck", "stribeck", "stribeck",  //
     EffectScope::Joint, "FST", EffectUnit::LikeFS, "N*m", "", "", "the Stribeck velocity", 0.05, true,
     "FST sign(qd) exp(-(qd / vs)^2); the diagnosis: averaged over a velocity spread", effect_laws::stribeck},
    {"constant torque offset", "offset", "offset", "torque_offset",  //
     EffectScope::Joint, "OFF", EffectUnit::LikeFS, "N*m", "", "", "", 0, false,
     "OFF (the twin's torque_offset t adds t to the drive: OFF = -t)", effect_laws::offset},
    {"backlash", "backlash", "", "backlash",  //
     EffectScope::Joint, "BL", EffectUnit::Own, "rad", "", "", "", 0, true,
     "BL (IA d2s/dt2 + FV ds/dt) / 2, s the smoothed sign of the mesh torque", nullptr},
    {"payload on the last link", "payload", "", "payload",  //
     EffectScope::Link, "PM PMX PMY PMZ", EffectUnit::Own, "kg", "", "", "", 0, true,
     "W times the last massive link's M, MX, MY, MZ", nullptr},
    {"torque-constant error", "torque_constant", "", "torque_constant_error",  //
     EffectScope::Joint, "KTE", EffectUnit::Own, "1", "", "", "", 0, false, "-KTE tau_model", nullptr},
    {"actuation delay", "actuation_delay", "", "actuation_delay",  //
     EffectScope::Robot, "DELAY", EffectUnit::Own, "s", "", "", "", 0, true, "DELAY d tau_model / dt", nullptr},
    {"encoder and current noise", "", "", "sensor_noise",  //
     EffectScope::Robot, "", EffectUnit::Own, "", "", "", "", 0, false, "none: a measurement effect", nullptr},
    {"timestamp jitter", "", "", "timestamp_jitter",  //
     EffectScope::Robot, "", EffectUnit::Own, "", "", "", "", 0, false, "none: a measurement effect", nullptr},
    {"dropped samples", "", "", "dropped_samples",  //
     EffectScope::Robot, "", EffectUnit::Own, "", "", "", "", 0, false, "none: a measurement effect", nullptr},
    {"external contact torque", "", "", "contact",  //
     EffectScope::Joint, "", EffectUnit::Own, "N*m", "", "", "", 0, false,
     "none: an external torque on a link for a while (a collision), which the log does not show", nullptr},
    {"direction-dependent viscous friction", "viscous_asymmetry", "viscous_asymmetry", "",  //
     EffectScope::Joint, "FVA", EffectUnit::LikeFV, "N*m*s/rad", "", "", "", 0, false, "FVA |qd|",
     effect_laws::viscous_asymmetry},
    {"position-dependent torque", "position_harmonics", "position_harmonics", "",  //
     EffectScope::Joint, "HS HC", EffectUnit::LikeFS, "N*m", "", "", "", 0, false, "HS_k sin(k q) + HC_k cos(k q)",
     effect_laws::position_harmonic},
    {"products of inertia", "inertia_products", "inertia_products", "",  //
     EffectScope::Link, "XY XZ YZ", EffectUnit::LikeXY, "kg*m^2", "XY XZ YZ", "", "", 0, false,
     "the full model's regressor columns of link j's XY, XZ, YZ", nullptr},
    {"Coulomb friction (OpenSYMORO's sign)", "", "coulomb", "",  //
     EffectScope::Joint, "FS", EffectUnit::LikeFS, "N*m", "FS", "", "", 0, true,
     "FS sign(qd), already in the files: the variant un-fixes it", nullptr},
    {"Tustin's Stribeck friction", "tustin_stribeck", "tustin_stribeck", "",  //
     EffectScope::Joint, "FSE", EffectUnit::LikeFS, "N*m", "", "", "the Stribeck velocity", 0.05, true,
     "FSE sign(qd) exp(-|qd| / vs)", effect_laws::tustin_stribeck},
}};

// The row of a name in one of the three columns (&EffectRow::diagnosis, ::variant, ::twin); null
// when none has it.
constexpr const EffectRow* find_effect(std::string_view EffectRow::*column, std::string_view name) {
  if (name.empty()) return nullptr;
  for (const EffectRow& row : kEffectTable)
    if (row.*column == name) return &row;
  return nullptr;
}

// Whether every name of a list has its row in a column: what the diagnosis's and the compiler's
// own orders of their effects static_assert.
template <std::size_t N>
constexpr bool every_name_has_a_row(std::string_view EffectRow::*column, const std::array<std::string_view, N>& names) {
  for (std::string_view name : names)
    if (!find_effect(column, name)) return false;
  return true;
}

// The words of a space-separated column (families, unfixes).
inline std::vector<std::string> effect_words(std::string_view text) {
  std::vector<std::string> words;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find(' ', at), text.size());
    if (end > at) words.emplace_back(text.substr(at, end - at));
    at = end + 1;
  }
  return words;
}

// How many words a space-separated column has, without making them.
constexpr int effect_word_count(std::string_view text) {
  int n = 0;
  for (std::size_t at = 0; at < text.size(); ++at) n += text[at] != ' ' && (at == 0 || text[at - 1] == ' ');
  return n;
}

// Whether a variant effect adds parameters of this family (OFF, FST, FVA, HS, HC, FC): a family
// of the effects, not of the rigid body or the drives.
inline bool variant_adds_family(std::string_view family) {
  for (const EffectRow& row : kEffectTable)
    if (!row.variant.empty() && row.unfixes.empty())
      for (const std::string& f : effect_words(row.families))
        if (f == family) return true;
  return false;
}

// The row whose joint law gives a parameter family's term (OFF, FST, FC, HS, ...), with the
// family's place among the row's families; a null row when no law gives it.
struct FamilyLaw {
  const EffectRow* row = nullptr;
  int family = 0;
};
inline FamilyLaw family_law(std::string_view family) {
  for (const EffectRow& row : kEffectTable)
    if (row.law) {
      const std::vector<std::string> words = effect_words(row.families);
      for (std::size_t k = 0; k < words.size(); ++k)
        if (words[k] == family) return {&row, static_cast<int>(k)};
    }
  return {};
}

// The name of an effect's parameter on a joint: the family, the joint, and the order of a
// harmonic ("OFF2", "FST1", "HS3_2").
inline std::string effect_parameter_name(std::string_view family, int joint, int order = 0) {
  std::string name = std::string(family) + std::to_string(joint);
  if (order > 0) name += "_" + std::to_string(order);
  return name;
}

// The parameters a row adds on a joint, in their canonical order: per order (position
// harmonics; none: one of each family), each family of the row.
struct EffectParameterName {
  std::string name, family;
  int order = 0;
};
inline std::vector<EffectParameterName> effect_parameter_names(const EffectRow& row, int joint,
                                                               const std::vector<int>& orders) {
  std::vector<EffectParameterName> out;
  for (int k : orders.empty() ? std::vector<int>{0} : orders)
    for (const std::string& family : effect_words(row.families))
      out.push_back({effect_parameter_name(family, joint, k), family, k});
  return out;
}

}  // namespace symoro
