// The ConsistencyStructure of a generated Model, and its base vector in the terms of that
// structure. A variant that fixes base parameters (crane_x7::reduced) is equivalent to its full
// model with those entries at their fixed values, so the structure is the full model's
// (Parent::base_from_standard) and the target is Model::to_parent(phi): a standard set that
// matched only the variant's own rows could give the fixed combinations any value.
// A variant's effect parameters (the last ne of its phi and of its standard vector: offsets,
// friction laws, position harmonics) follow the parent's base vector in the target and map onto
// themselves (an identity block of B beside the parent's): free, or >= 0 where effect_table.hpp
// says the effect is physical only with a positive level (Coulomb, Stribeck).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "symoro/effect_table.hpp"
#include "symoro/identify/physical_consistency.hpp"
#include "symoro/model_info.hpp"

namespace symoro::identify {
namespace detail {

template <class Model, class = void>
struct HasEffects : std::false_type {};
template <class Model>
struct HasEffects<Model, std::void_t<decltype(Model::ne)>> : std::true_type {};

// How many effect parameters a Model has (0 for a model without effects).
template <class Model>
constexpr int effect_count() {
  if constexpr (HasEffects<Model>::value)
    return Model::ne;
  else
    return 0;
}

// Whether an effect family's parameter must be >= 0: the first family of a row that is
// physical only with a positive level (FC, FST, FSE).
inline bool positive_effect_family(const std::string& family) {
  const FamilyLaw law = family_law(family);
  return law.row && law.row->positive && law.family == 0;
}

inline int inertial_slot(const std::string& family) {
  static const char* order[10] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"};
  for (int i = 0; i < 10; ++i)
    if (family == order[i]) return i;
  return -1;
}

inline StandardGroup standard_group(const std::string& family) {
  const int slot = inertial_slot(family);
  if (slot == 9) return StandardGroup::Mass;
  if (slot >= 6) return StandardGroup::FirstMoment;
  if (slot >= 0) return StandardGroup::Inertia;
  if (family == "IA") return StandardGroup::RotorInertia;
  if (family == "FV") return StandardGroup::Viscous;
  if (family == "FS") return StandardGroup::Coulomb;
  return StandardGroup::Other;
}

// The prior of a solve over a standard vector of ns entries whose last ne are effect parameters:
// zero when empty; the parent's standard prior (ns - ne entries) gets 0 for the effects.
inline Eigen::VectorXd standard_prior(const Eigen::VectorXd& prior, int ns, int ne) {
  if (!prior.size()) return Eigen::VectorXd::Zero(ns);
  if (prior.size() == ns) return prior;
  if (prior.size() != ns - ne)
    throw std::invalid_argument("physical consistency: a prior of " + std::to_string(prior.size()) +
                                " standard parameters, expected " + std::to_string(ns - ne) + " or " +
                                std::to_string(ns));
  Eigen::VectorXd out = Eigen::VectorXd::Zero(ns);
  out.head(ns - ne) = prior;
  return out;
}

}  // namespace detail

// The structure of a model whose standard parameters are `standard`, B its full model's
// base_from_standard (np x ns, column k the image of unit vector k). For a generated Model
// (below) and a loaded one (loaded_model.cpp) alike.
inline ConsistencyStructure consistency_structure(const std::vector<StandardParameterInfo>& standard,
                                                  Eigen::MatrixXd B) {
  ConsistencyStructure c;
  c.B = std::move(B);
  for (std::size_t k = 0; k < standard.size(); ++k) {
    const StandardParameterInfo& p = standard[k];
    const std::string family = p.family;
    c.names.emplace_back(p.name);
    c.group.push_back(detail::standard_group(family));
    const int slot = detail::inertial_slot(family);
    if (slot >= 0) {
      auto it = c.links.begin();
      while (it != c.links.end() && it->link != p.joint) ++it;
      if (it == c.links.end()) {
        c.links.emplace_back();
        c.links.back().link = p.joint;
        it = c.links.end() - 1;
      }
      it->index[static_cast<std::size_t>(slot)] = static_cast<int>(k);
    }
    if (family == "IA" || family == "FV" || family == "FS" || detail::positive_effect_family(family))
      c.nonnegative.push_back(static_cast<int>(k));
  }
  return c;
}

// B of a variant with ne effect parameters: the parent's B, then an identity block for them.
inline Eigen::MatrixXd with_effect_block(const Eigen::MatrixXd& parent_B, int ne) {
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(parent_B.rows() + ne, parent_B.cols() + ne);
  B.topLeftCorner(parent_B.rows(), parent_B.cols()) = parent_B;
  B.bottomRightCorner(ne, ne).setIdentity();
  return B;
}

template <class Model>
ConsistencyStructure consistency_structure() {
  using Parent = typename Model::Parent;
  constexpr int ne = detail::effect_count<Model>();
  static_assert(Parent::ns == Model::ns - ne,
                "consistency_structure: the variant's standard vector differs from its parent's");
  Eigen::MatrixXd B(Parent::np, Parent::ns);
  for (int k = 0; k < Parent::ns; ++k)
    B.col(k) = Parent::base_from_standard(Eigen::Matrix<double, Parent::ns, 1>::Unit(k));
  return consistency_structure({Model::standard_parameters.begin(), Model::standard_parameters.end()},
                               ne ? with_effect_block(B, ne) : std::move(B));
}

// The target of consistent_standard_parameters for a Model's phi: the full base vector, then
// the effect parameters.
template <class Model, class Phi>
Eigen::VectorXd consistency_target(const Eigen::MatrixBase<Phi>& phi) {
  constexpr int ne = detail::effect_count<Model>();
  const Eigen::Matrix<double, Model::np, 1> own(phi);
  Eigen::VectorXd target(Model::Parent::np + ne);
  target.head(Model::Parent::np) = Model::to_parent(own).template cast<double>();
  target.tail(ne) = own.tail(ne);
  return target;
}

// The same solve from a Model's phi.
template <class Model, class Phi>
ConsistencyResult consistent_standard_parameters(const Eigen::MatrixBase<Phi>& phi, const Eigen::VectorXd& prior,
                                                 const ConsistencyOptions& options = {}) {
  return consistent_standard_parameters(consistency_structure<Model>(), consistency_target<Model>(phi), prior, options);
}

}  // namespace symoro::identify
