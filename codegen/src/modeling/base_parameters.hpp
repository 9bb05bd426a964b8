// Base (grouped) inertial parameters of a serial or tree robot in modified DH.
//
// Two steps. First Khalil's general grouping rules, exact and symbolic, from the last link to
// the first:
//   - revolute joint j: the part of link j that a rotation about z_j leaves unchanged (mass M_j,
//     first moment (0, 0, MZ_j), inertia diag(YY_j, YY_j, 0)) moves rigidly with link ant(j):
//     it goes there through the constant transform of the joint (the parallel-axis theorem
//     with first moments), and link j keeps XXR_j = XX_j - YY_j, YY_j = MZ_j = M_j = 0;
//   - prismatic joint j: link j turns with its antecedent, so its inertia tensor goes there,
//     rotated: J_ant += R J_j R^T.
// What reaches the fixed base has no effect and is dropped. Then the particular cases, found
// numerically on the regressor of the grouped parameters at random states (geometric symbols
// at generic random values, as a symbolic tool treats them): a parameter whose column is zero
// has no effect and is dropped (links that only turn about one fixed axis, first moments along
// gravity's axis, ...), and a rotor inertia IA_j whose column equals that of ZZ_j (M_j for a
// prismatic joint) is added to it. The remaining columns must be independent; a robot whose
// geometry leaves another dependency is refused, naming the parameters.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "description.hpp"

namespace symoro::codegen::modeling {

struct BaseParameters {
  std::vector<LinkParameters> links;  // per slot: the base parameter's symbol, or 0
  // Definitions in order, each over the standard parameters, the geometric symbols and earlier
  // definitions: what regp.txt writes (grouped intermediates such as MR5 included).
  std::vector<std::pair<std::string, NodeId>> definitions;
  std::vector<std::string> names;  // the base parameters in table order (link by link)
  std::vector<std::string> notes;  // what the numeric step decided, for the user
};

BaseParameters base_parameters(ExprGraph& g, const Description& d);

}  // namespace symoro::codegen::modeling
