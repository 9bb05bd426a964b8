// Model-gap effects of robot.yaml variants (`effects:`): their kinds in canonical order, the
// parameters they add and their torque terms. Names, the families an effect un-fixes or adds
// and their units are the effect table's (runtime/include/symoro/effect_table.hpp, which the
// diagnosis and the twin read too). See docs/generated-api.md, "Effects in variants".
//
//   coulomb             un-fixes FS<j> (the files already have FSj*sign(QPj))
//   inertia_products    un-fixes the XY, XZ, YZ base parameters of link j
//   offset              OFF<j>    [N*m | N]           OFFj * 1
//   stribeck            FST<j>    [N*m | N]           FSTj * sign(QPj) * exp(-(QPj/v)^2)
//   viscous_asymmetry   FVA<j>    [N*m*s/rad | N*s/m] FVAj * |QPj|  (QPj*sign(QPj))
//   position_harmonics  HS<j>_<k>, HC<j>_<k> [N*m | N]  HSj_k*sin(k*qj), HCj_k*cos(k*qj)
//   smooth_coulomb      FC<j>     [N*m | N]           FCj * tanh(QPj/v); fixes FSj to 0 (the
//                       files' FSj*sign(QPj) would be the same effect with a noise-biased column)
//   tustin_stribeck     FSE<j>    [N*m | N]           FSEj * sign(QPj) * exp(-|QPj|/v)
// A row added to the table compiles from its row alone: its law gives the term.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"

namespace symoro {
struct EffectRow;
}

namespace symoro::codegen {

// In catalogue order, which is also the order of the parameters the effects add. A kind past
// SmoothCoulomb is a variant effect added to the table after these (effect_row tells it).
enum class EffectKind {
  Coulomb,
  InertiaProducts,
  Offset,
  Stribeck,
  ViscousAsymmetry,
  PositionHarmonics,
  SmoothCoulomb
};

// The robot.yaml key of an effect ("coulomb", "inertia_products", ...) and back.
const std::string& effect_name(EffectKind kind);
std::optional<EffectKind> effect_kind(const std::string& name);
// Every key, comma separated, in catalogue order (for messages).
std::string effect_names();

// Whether the effect names links (inertia_products) rather than joints.
bool effect_on_links(EffectKind kind);
// The base parameter families the effect un-fixes on its joint or link: {"FS"} for coulomb,
// {"XY", "XZ", "YZ"} for inertia_products, none for the effects that add parameters.
const std::vector<std::string>& unfixed_families(EffectKind kind);

// Whether an effect takes {joints: [...], velocity: v} (stribeck, smooth_coulomb); the row says
// what the velocity is called and its default when robot.yaml gives none.
bool effect_has_velocity(EffectKind kind);
// The effect's row of the effect table.
const EffectRow& effect_row(EffectKind kind);

// One effect on one joint (or link) of a variant, as robot.yaml states it.
struct EffectSpec {
  EffectKind kind = EffectKind::Offset;
  int index = 0;             // 1-based joint, or link for inertia_products
  double velocity = 0;       // stribeck, smooth_coulomb: the velocity scale (> 0)
  std::vector<int> orders;   // position_harmonics: the harmonic orders, ascending, >= 1
  int line = 0, column = 0;  // the robot.yaml node that names the joint (for errors)
};

// A parameter an effect adds: identified, appended after the base parameters.
struct EffectParameter {
  std::string name;    // OFF2, FST2, FVA1, HS3_1, HC3_1
  std::string family;  // OFF, FST, FVA, HS, HC
  int joint = 0;       // 1-based
  std::string unit;
  int order = 0;        // HS, HC: the harmonic order
  double velocity = 0;  // FST: the Stribeck velocity; FC: the tanh velocity scale
};

// The parameters the effects add, in canonical order: effect kind in catalogue order, joint
// ascending, order ascending, HS before HC for one order. `unit(family, joint)` is the unit of
// the base family FS or FV on that joint (prismatic joints have their own); the torque-like
// parameters take the FS unit, FVA the FV unit.
std::vector<EffectParameter> effect_parameters(const std::vector<EffectSpec>& effects,
                                               const std::function<std::string(const std::string&, int)>& unit);

// The term a parameter multiplies on its joint's row (its regressor entry there), over the
// nodes of that joint's position q and velocity qd: its row's joint law, in the graph.
NodeId effect_term(ExprGraph& g, const EffectParameter& p, NodeId q, NodeId qd);

// The same term as text for `symoroc info`, e.g. "sign(QP2)*exp(-(QP2/0.05)^2)".
std::string effect_term_text(const EffectParameter& p, const std::string& q, const std::string& qd);

}  // namespace symoro::codegen
