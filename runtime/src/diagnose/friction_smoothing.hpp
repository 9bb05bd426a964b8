// One velocity spread for a joint's friction (selection.hpp, after the forward steps).
//
// Coulomb and Stribeck columns are their laws averaged over the spread of the true velocity
// about the logged one (effects.hpp): quantization, and a servo hunting about a held posture.
// The spread is one property of the joint's velocity, the same for every friction term of the
// joint, but the forward steps choose terms one at a time, and the first chooses its spread
// alone: a Coulomb term taken first on a joint that also has static (Stribeck) friction takes
// too small a spread, whose sharper edge stands in for the extra friction at low speed, and
// the Stribeck term after it is left a fraction of its size (an independent arm with 0.05 N m
// Coulomb and 0.06 N m Stribeck friction: 0.055 N m Coulomb named alone).
//
// So every joint with friction named has it chosen again, as a whole, from the refined
// spreads and velocities (friction_options): Coulomb alone, Stribeck alone, or both at one
// spread, each refitted with the other named effects, by the joint's held-out residual. Both
// terms are taken only when the pair lowers it by `min_heldout_gain` below the best single
// term; the backward check then judges each term as it judges every other.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "symoro/diagnose/selection.hpp"

namespace symoro::diagnose::detail {

// `chosen` and `effects` (the same effects, in order) are rewritten joint by joint.
void choose_friction_smoothing(const DesignStack& train, const DesignStack& heldout, const SelectionOptions& options,
                               const Eigen::VectorXd& weights, std::vector<Candidate>& chosen,
                               std::vector<SelectedEffect>& effects);

}  // namespace symoro::diagnose::detail
