// The one table of model-gap effects: what the diagnosis looks for, what a robot.yaml variant
// compiles (`effects:`), and what the twin simulates, one row per physical effect with its name
// in each of the three. The diagnosis (diagnose/effects.cpp), the compiler (codegen/src/effects.cpp)
// and the twin's configuration (twin/config.cpp) take their names, titles, parameter families,
// units and physical checks from here; tests/runtime/test_diagnose_effects.cpp checks, row by row,
// that the three evaluate the same term. Header-only and free of other headers of the project:
// symoroc reads it without linking the runtime.
//
// Adding a friction model: a row here, its term in the diagnosis (effect_terms, effect_columns)
// and, if a variant can carry it, in the compiler (effect_term, effect_term_text); see
// docs/architecture.md, "Where to add an effect".
#pragma once

#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <vector>

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
  bool velocity_scale;       // a variant gives it {joints: [...], velocity: v}
  // Physical only with a positive first parameter (a friction level, a play, a mass, a delay):
  // a fit that makes it negative is absorbing another misfit.
  bool positive;
  std::string_view term;  // the torque on its joint's row, per parameter
};

// The rows, in the twin's order of effects first (its names() and log notes keep that order).
inline constexpr std::array<EffectRow, 14> kEffectTable{{
    {"Coulomb friction", "coulomb", "smooth_coulomb", "coulomb", EffectScope::Joint, "FC", EffectUnit::LikeFS, "N*m",
     "", true, true,
     "FC tanh(qd / v); the diagnosis: the sign averaged over a velocity spread s (erf), v = s sqrt(pi / 2)"},
    {"Stribeck friction", "stribeck", "stribeck", "stribeck", EffectScope::Joint, "FST", EffectUnit::LikeFS, "N*m", "",
     true, true, "FST sign(qd) exp(-(qd / vs)^2)"},
    {"constant torque offset", "offset", "offset", "torque_offset", EffectScope::Joint, "OFF", EffectUnit::LikeFS,
     "N*m", "", false, false, "OFF (the twin's torque_offset t adds t to the drive: OFF = -t)"},
    {"backlash", "backlash", "", "backlash", EffectScope::Joint, "BL", EffectUnit::Own, "rad", "", false, true,
     "BL (IA d2s/dt2 + FV ds/dt) / 2, s the smoothed sign of the mesh torque"},
    {"payload on the last link", "payload", "", "payload", EffectScope::Link, "PM PMX PMY PMZ", EffectUnit::Own, "kg",
     "", false, true, "W times the last massive link's M, MX, MY, MZ"},
    {"torque-constant error", "torque_constant", "", "torque_constant_error", EffectScope::Joint, "KTE",
     EffectUnit::Own, "1", "", false, false, "-KTE tau_model"},
    {"actuation delay", "actuation_delay", "", "actuation_delay", EffectScope::Robot, "DELAY", EffectUnit::Own, "s", "",
     false, true, "DELAY d tau_model / dt"},
    {"encoder and current noise", "", "", "sensor_noise", EffectScope::Robot, "", EffectUnit::Own, "", "", false, false,
     "none: a measurement effect"},
    {"timestamp jitter", "", "", "timestamp_jitter", EffectScope::Robot, "", EffectUnit::Own, "", "", false, false,
     "none: a measurement effect"},
    {"dropped samples", "", "", "dropped_samples", EffectScope::Robot, "", EffectUnit::Own, "", "", false, false,
     "none: a measurement effect"},
    {"direction-dependent viscous friction", "viscous_asymmetry", "viscous_asymmetry", "", EffectScope::Joint, "FVA",
     EffectUnit::LikeFV, "N*m*s/rad", "", false, false, "FVA |qd|"},
    {"position-dependent torque", "position_harmonics", "position_harmonics", "", EffectScope::Joint, "HS HC",
     EffectUnit::LikeFS, "N*m", "", false, false, "HS_k sin(k q) + HC_k cos(k q)"},
    {"products of inertia", "inertia_products", "inertia_products", "", EffectScope::Link, "XY XZ YZ",
     EffectUnit::LikeXY, "kg*m^2", "XY XZ YZ", false, false,
     "the full model's regressor columns of link j's XY, XZ, YZ"},
    {"Coulomb friction (OpenSYMORO's sign)", "", "coulomb", "", EffectScope::Joint, "FS", EffectUnit::LikeFS, "N*m",
     "FS", false, true, "FS sign(qd), already in the files: the variant un-fixes it"},
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

// Whether a variant effect adds parameters of this family (OFF, FST, FVA, HS, HC, FC): a family
// of the effects, not of the rigid body or the drives.
inline bool variant_adds_family(std::string_view family) {
  for (const EffectRow& row : kEffectTable)
    if (!row.variant.empty() && row.unfixes.empty())
      for (const std::string& f : effect_words(row.families))
        if (f == family) return true;
  return false;
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
