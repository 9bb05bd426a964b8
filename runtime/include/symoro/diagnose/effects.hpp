// The library of candidate effects a model may be missing. Each candidate is a named term with
// physical units, acting on one joint (or one link, or the whole robot), and linear in its own
// parameters given the data: its regressor columns are added to the identified model's
// regressor, so that "is it there, and how large" is a nested least-squares question.
//
//   effect             parameters (unit)               torque on joint j
//   coulomb            FS<j> (N m), vc fixed            FS tanh(qd/vc)   (OpenSYMORO's FS sign(qd)
//                                                       as vc -> 0; the zero-phase filter smooths
//                                                       the step, so a few widths are tried)
//   stribeck           FST<j> (N m), vs fixed           FST sign(qd) exp(-(qd/vs)^2)
//   offset             OFF<j> (N m)                     OFF
//   viscous_asymmetry  FVA<j> (N m s/rad)               FVA |qd|   (FV + FVA forward, FV - FVA back)
//   position_harmonics HS<j>_k, HC<j>_k (N m)           HS sin(k q) + HC cos(k q), k = 1, 2
//   inertia_products   the full model's XY/XZ/YZ of link j (kg m^2), columns from its regressor
//   payload            PM (kg), PMX, PMY, PMZ (kg m)   a mass m at p on the last massive link: W times
//                      of that link (standard M, MX, MY,   the base parameters it adds (its rotational
//                      MZ: m, m p)                          inertia m |p|^2 is second order and left out).
//                                                       Only against held parameters (--params): a
//                                                       refit absorbs it into the link's base parameters
//   torque_constant    KTE<j> (1)                       tau_meas = tau / (1 + KTE): column -tau_model
//   actuation_delay    DELAY (s), all joints            tau_meas(t) = tau(t + DELAY): column d tau_model/dt
//   backlash           BL<j> (rad, total play)          the rotor leads the link by BL/2 sign(mesh
//                                                       torque): column (IA d2s/dt2 + FV ds/dt) / 2,
//                                                       s made at the logs' rate and low-passed as
//                                                       the data were (DesignStack::filtered)
//   tustin_stribeck    FSE<j> (N m), vs fixed           FSE sign(qd) exp(-|qd|/vs), averaged over the spread:
//                                                       a row added to the effect table, known by its law
//                                                       alone and looked for only when --only names it
// The last three are linearizations about the current fit (their columns use its torque), so
// the selection re-evaluates them after every step. Names, families, units, the physical check,
// the variant effect each compiles to (coulomb -> smooth_coulomb) and the laws of the joint
// effects are the effect table's (symoro/effect_table.hpp); what is here is how the diagnosis
// looks for each: Coulomb and Stribeck friction averaged over the logs' velocity spread, the
// linearized effects' columns, the payload's.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/diagnose/design_stack.hpp"
#include "symoro/effect_table.hpp"

namespace symoro::diagnose {

// A kind past Payload is a row added to the effect table with a diagnosis name and a joint law:
// the diagnosis knows it by its row alone (effect_info(kind).row).
enum class EffectKind {
  Coulomb,
  Stribeck,
  Offset,
  ViscousAsymmetry,
  PositionHarmonics,
  InertiaProducts,
  TorqueConstant,
  ActuationDelay,
  Backlash,
  Payload,
};

// A diagnosis effect: its kind and its row of the effect table (symoro/effect_table.hpp: name,
// title, parameter families and units, the physical check, the variant effect it compiles to).
struct EffectInfo {
  EffectKind kind;
  const EffectRow* row;
  const char* name;   // row->diagnosis, e.g. "coulomb"
  const char* title;  // row->title, "Coulomb friction"
};

const std::vector<EffectInfo>& effect_catalogue();
// Whether the diagnosis looks for an effect only when CandidateOptions::only names it: a row added
// to the effect table, known by its law alone (a law close to one the diagnosis tries already
// would split the effect between the two).
bool only_when_named(EffectKind kind);
const EffectInfo& effect_info(EffectKind kind);
// By name; throws std::invalid_argument listing the known names.
EffectKind effect_kind(const std::string& name);

struct Candidate {
  EffectKind kind = EffectKind::Offset;
  int joint = 0;                    // 1-based joint or link (payload: its link); 0 for the whole robot
  double stribeck_velocity = 0.05;  // rad/s
  // rad/s, Coulomb and Stribeck: the spread of the true velocity about the logged one near
  // rest (quantization, a servo hunting about a held posture). The friction the torque shows
  // is the friction law averaged over that spread: the columns are the law's expectation
  // under it (a sharp sign gave a Stribeck level a third of its size), and the magnitudes are
  // the law's own.
  double coulomb_velocity = 0.01;
  double velocity = 0;            // rad/s: the velocity scale of an added row's law that has one
  std::vector<int> orders;        // position_harmonics
  std::vector<int> full_columns;  // inertia_products: columns of DesignStack::full_extra
  std::vector<std::string> parameters, units;
  std::string label() const;  // "coulomb friction, joint 2 (shoulder_tilt)" style
  std::string key() const;    // "coulomb:2", unique per candidate
};

struct CandidateOptions {
  // rad/s: the forward steps' Coulomb candidates, one per velocity spread, and Stribeck
  // candidates, one per velocity and spread of at most half of it (closer, a Stribeck term is
  // the spread's shape, not friction).
  std::vector<double> coulomb_velocities{0.01, 0.03, 0.1};
  std::vector<double> stribeck_velocities{0.02, 0.05, 0.1};
  // What a joint's friction is chosen from again once named (friction_options; a superset).
  std::vector<double> refined_spreads{0.005, 0.01, 0.02, 0.03, 0.04, 0.06, 0.1};
  std::vector<double> refined_stribeck_velocities{0.02, 0.05, 0.07, 0.1, 0.15};
  std::vector<int> harmonic_orders{1, 2};
  // rad/s: the velocity scales an added row's law that has one is tried at, one candidate each,
  // and those a friction law of an added row is chosen from again (friction_options).
  std::vector<double> law_velocities{0.02, 0.05, 0.1};
  std::vector<double> refined_law_velocities{0.02, 0.03, 0.05, 0.07, 0.1, 0.15};
  // Effect names to consider (empty: the diagnosis's own; a row added to the effect table is
  // considered only when named here).
  std::vector<std::string> only;
};

// A joint's candidate with its parameters named and united as the effect table says (one per
// family, and per order for position harmonics; revolute units), at the default velocities.
Candidate joint_candidate(EffectKind kind, int joint, const std::vector<int>& orders = {});

// Every candidate the data and the identified model allow: not one the model already has
// (a parameter of the same name), inertia products only for links whose full-model columns
// exist in the stack, torque-constant and backlash only where IA and FV are identified.
std::vector<Candidate> candidates(const DesignStack& d, const CandidateOptions& options = {});
// Whether an effect is one of a joint's friction terms, chosen again as a whole once named:
// Coulomb, Stribeck, or an added row's law with a velocity scale and a positive level.
bool friction_law(EffectKind kind);
// Joint j's friction candidates over the refined spreads and velocities (when the options allow
// those effects): what the joint's friction is chosen from once named.
std::vector<Candidate> friction_options(const DesignStack& d, const CandidateOptions& options, int joint);

// What a linearized candidate needs from the current fit.
struct FitState {
  Eigen::VectorXd tau_model;  // stacked model torque (W phi + tau0 + selected effects)
  Eigen::VectorXd phi;        // identified parameters (for IA, FV)
};

// Whether a candidate's columns depend on the samples alone (then they are computed at the
// log's rate, before the low-pass, by stack_builder.hpp) rather than on the current fit.
bool sample_local(EffectKind kind);
// A sample-local candidate's terms at one sample of its joint (one value per parameter).
void effect_terms(const Candidate& c, double q, double qd, double* out);

// The candidate's columns, (samples * joints) x parameters: the precomputed terms of the
// stack when it has them, else evaluated on the stack's samples.
Eigen::MatrixXd effect_columns(const Candidate& c, const DesignStack& d, const FitState& fit);

// The velocity scale of the variant effect the candidate compiles to (robot.yaml's {joints,
// velocity}): Stribeck's own velocity; for Coulomb friction the tanh width whose slope at rest is
// the erf's, spread sqrt(pi / 2); 0 for an effect without one.
double variant_velocity(const Candidate& c);

// False when fitted parameters contradict the effect's physics (negative Coulomb or Stribeck
// level, negative play, a negative payload mass or actuation delay): such a fit is absorbing
// some other misfit and is not an effect.
bool physical(const Candidate& c, const Eigen::VectorXd& theta);

// The candidate's magnitude from its fitted parameters, in its unit (e.g. the amplitude of
// each harmonic; the play for backlash), with a text like "0.081 N m".
struct Magnitude {
  std::vector<double> values;
  std::vector<std::string> names;
  std::string text;
};
Magnitude magnitude(const Candidate& c, const Eigen::VectorXd& theta, const Eigen::VectorXd& sd);

}  // namespace symoro::diagnose
