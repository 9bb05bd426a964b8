// The twin's true parameters for a generated Model (its full model): standard parameters from
// the CAD chain (plus the payload when enabled), base parameters through base_from_standard,
// and the link-side parameters used when backlash separates the rotors from the links.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/twin/config.hpp"
#include "symoro/twin/standard_parameters.hpp"

namespace symoro::twin {

template <class Model>
struct Truth {
  std::vector<LinkInertial> links;                 // per model frame, with the payload
  Eigen::Matrix<double, Model::ns, 1> standard;    // Coulomb (FS) is 0: the twin applies its own
  Eigen::Matrix<double, Model::np, 1> phi;         // rigid drives: rotor inertia and viscous friction in the model
  Eigen::Matrix<double, Model::np, 1> phi_links;   // the same without rotor and viscous terms of backlash joints
};

template <class Model>
std::vector<StandardParameterInfo> standard_parameter_list() {
  return {Model::standard_parameters.begin(), Model::standard_parameters.end()};
}

template <class Model>
std::vector<FrameInfo> frame_list() {
  return {Model::frames.begin(), Model::frames.end()};
}

// The last frame that carries a mass parameter: where a payload goes.
template <class Model>
int payload_frame() {
  int last = 0;
  for (const auto& p : Model::standard_parameters)
    if (std::string(p.family) == "M") last = std::max(last, p.joint);
  return last;
}

template <class Model>
Truth<Model> make_truth(const TwinConfig& c) {
  constexpr int n = Model::nq;
  Truth<Model> t;
  t.links = model_link_inertials(c.chain, frame_list<Model>(), c.path);
  if (c.effects.payload && c.effects.payload_mass > 0) {
    const int f = payload_frame<Model>();
    if (f == 0) throw DataError(c.path, 0, "payload: the model has no link with a mass parameter");
    add_point_mass(t.links[f - 1], c.effects.payload_mass, c.effects.payload_com);
  }
  const auto names = standard_parameter_list<Model>();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  t.standard = standard_vector(names, t.links, c.rotor_inertia, c.viscous, zero, c.path);
  t.phi = Model::base_from_standard(t.standard);

  Eigen::VectorXd ia = c.rotor_inertia, fv = c.viscous;
  if (c.effects.backlash)
    for (int j = 0; j < n; ++j)
      if (c.effects.backlash_width(j) > 0) ia(j) = fv(j) = 0;
  const Eigen::Matrix<double, Model::ns, 1> s_links = standard_vector(names, t.links, ia, fv, zero, c.path);
  t.phi_links = Model::base_from_standard(s_links);
  return t;
}

// The twin's true identified parameters of a Model (any variant): its base parameters plus what
// the variant's extra parameters can represent of the twin's hidden effects. Coulomb friction
// (FS or the smooth FC, the twin's smoothed Coulomb torque) and offsets (OFFj = minus the twin's external offset
// torque: the motor's holding torque); every other effect parameter is 0 in the truth.
template <class Model>
Eigen::Matrix<double, Model::np, 1> identified_truth(const TwinConfig& c) {
  Eigen::Matrix<double, Model::ns, 1> s = make_truth<Model>(c).standard;
  for (int k = 0; k < Model::ns; ++k) {
    const std::string family = Model::standard_parameters[k].family;
    const int j = Model::standard_parameters[k].joint - 1;
    if (j < 0 || j >= Model::nq) continue;
    if ((family == "FS" || family == "FC") && c.effects.coulomb) s(k) = c.effects.coulomb_torque(j);
    if (family == "OFF" && c.effects.torque_offset) s(k) = -c.effects.offset_torque(j);
  }
  return Model::base_from_standard(s);
}

}  // namespace symoro::twin
