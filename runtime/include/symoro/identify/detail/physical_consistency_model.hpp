// The ConsistencyStructure of a generated Model, and its base vector in the terms of that
// structure. A variant that fixes base parameters (crane_x7::reduced) is equivalent to its full
// model with those entries at their fixed values, so the structure is the full model's
// (Parent::base_from_standard) and the target is Model::to_parent(phi): a standard set that
// matched only the variant's own rows could give the fixed combinations any value.
#pragma once

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/physical_consistency.hpp"
#include "symoro/model_info.hpp"

namespace symoro::identify {
namespace detail {

template <class Model, class = void>
struct HasEffects : std::false_type {};
template <class Model>
struct HasEffects<Model, std::void_t<decltype(Model::ne)>> : std::true_type {};

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
    if (family == "IA" || family == "FV" || family == "FS") c.nonnegative.push_back(static_cast<int>(k));
  }
  return c;
}

template <class Model>
ConsistencyStructure consistency_structure() {
  // Effect parameters map onto themselves through a variant's own base_from_standard, which the
  // parent's does not have: not supported yet.
  static_assert(!detail::HasEffects<Model>::value, "consistency_structure: variants with effects are not supported");
  using Parent = typename Model::Parent;
  static_assert(Parent::ns == Model::ns,
                "consistency_structure: the variant's standard vector differs from its parent's");
  Eigen::MatrixXd B(Parent::np, Parent::ns);
  for (int k = 0; k < Parent::ns; ++k)
    B.col(k) = Parent::base_from_standard(Eigen::Matrix<double, Parent::ns, 1>::Unit(k));
  return consistency_structure({Model::standard_parameters.begin(), Model::standard_parameters.end()}, std::move(B));
}

// The target of consistent_standard_parameters for a Model's phi: the full base vector.
template <class Model, class Phi>
Eigen::VectorXd consistency_target(const Eigen::MatrixBase<Phi>& phi) {
  return Model::to_parent(Eigen::Matrix<double, Model::np, 1>(phi)).template cast<double>();
}

// The same solve from a Model's phi.
template <class Model, class Phi>
ConsistencyResult consistent_standard_parameters(const Eigen::MatrixBase<Phi>& phi, const Eigen::VectorXd& prior,
                                                 const ConsistencyOptions& options = {}) {
  return consistent_standard_parameters(consistency_structure<Model>(), consistency_target<Model>(phi), prior, options);
}

}  // namespace symoro::identify
