#include "symoro/twin/truth.hpp"

#include <algorithm>
#include <string>

#include "symoro/error.hpp"

namespace symoro::twin {

int payload_frame(const robot::ModelHandle& model) {
  int last = 0;
  for (const auto& p : model.standard_parameters())
    if (std::string(p.family) == "M") last = std::max(last, p.joint);
  return last;
}

Truth make_truth(const robot::ModelHandle& model, const TwinConfig& c) {
  const int n = model.nq();
  Truth t;
  t.links = model_link_inertials(c.chain, model.frames(), c.path);
  if (c.effects.payload && c.effects.payload_mass > 0) {
    const int f = payload_frame(model);
    if (f == 0) throw DataError(c.path, 0, "payload: the model has no link with a mass parameter");
    add_point_mass(t.links[f - 1], c.effects.payload_mass, c.effects.payload_com);
    t.links[f - 1].J += c.effects.payload_inertia;
  }
  const auto& names = model.standard_parameters();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  t.standard = standard_vector(names, t.links, c.rotor_inertia, c.viscous, zero, c.path);
  t.phi = model.base_from_standard(t.standard);

  Eigen::VectorXd ia = c.rotor_inertia, fv = c.viscous;
  if (c.effects.backlash)
    for (int j = 0; j < n; ++j)
      if (c.effects.backlash_width(j) > 0) ia(j) = fv(j) = 0;
  t.phi_links = model.base_from_standard(standard_vector(names, t.links, ia, fv, zero, c.path));
  return t;
}

Eigen::VectorXd identified_truth(const robot::ModelHandle& model, const TwinConfig& c) {
  Eigen::VectorXd s = make_truth(model, c).standard;
  const auto& names = model.standard_parameters();
  for (int k = 0; k < model.ns(); ++k) {
    const std::string family = names[k].family;
    const int j = names[k].joint - 1;
    if (j < 0 || j >= model.nq()) continue;
    if ((family == "FS" || family == "FC") && c.effects.coulomb) s(k) = c.effects.coulomb_torque(j);
    if (family == "OFF" && c.effects.torque_offset) s(k) = -c.effects.offset_torque(j);
  }
  return model.base_from_standard(s);
}

}  // namespace symoro::twin
