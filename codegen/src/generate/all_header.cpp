// all.hpp: every header of a model, and `Model`, a type naming its constants and functions so
// that generic code (the tests, the runtime) takes a model as a template argument.
#include "headers.hpp"

namespace symoro::codegen::generate {

std::string all_header(const ModelContext& c) {
  std::string s = c.banner("The whole model and `Model`, a type that names it for generic code.");
  for (const char* f :
       {"model.hpp", "base_parameters.hpp", "regressor.hpp", "inverse_dynamics.hpp", "inertia.hpp",
        "nonlinear_effects.hpp", "forward_dynamics.hpp", "inverse_dynamics_derivatives.hpp",
        "forward_dynamics_derivatives.hpp", "inertia_derivatives.hpp", "forward_kinematics.hpp", "jacobian.hpp"})
    s += c.include_self(f);
  s += "\n#include <utility>\n";
  if (!c.variant.empty()) s += "#include \"symoro/" + c.r.name + "/all.hpp\"\n";
  s += "\n" + c.open();
  s += "struct Model {\n";
  s += "  static constexpr int nq = " + c.ns + "::nq;\n";
  s += "  static constexpr int np = " + c.ns + "::np;\n";
  s += "  static constexpr int ns = " + c.ns + "::ns;\n";
  s += "  static constexpr int nf = " + c.ns + "::nf;\n";
  if (c.ne() > 0) s += "  static constexpr int ne = " + c.ns + "::ne;\n";
  for (const char* v : {"robot_name", "variant_name", "description"})
    s += "  static constexpr const char* " + std::string(v) + " = " + c.ns + "::" + v + ";\n";
  for (const char* v :
       {"parameters", "fixed_parameters", "parent_index", "standard_parameters", "joints", "frames", "gravity"})
    s += "  static constexpr const auto& " + std::string(v) + " = " + c.ns + "::" + v + ";\n";
  if (c.ne() > 0) s += "  static constexpr const auto& effect_parameters = " + c.ns + "::effect_parameters;\n";
  s += "  // The robot's full model (this type itself for the full model).\n";
  s += "  using Parent = " + (c.variant.empty() ? std::string("Model") : "::symoro::" + c.r.name + "::Model") + ";\n";
  for (const char* t :
       {"InertiaBasis", "InertiaDerivatives", "InverseDynamicsDerivatives", "ForwardDynamicsDerivatives"})
    s += "  template <class Scalar>\n  using " + std::string(t) + " = " + c.ns + "::" + t + "<Scalar>;\n";
  for (const char* f :
       {"base_from_standard", "to_parent", "from_parent", "regressor", "fixed_torque", "inverse_dynamics", "inertia",
        "inertia_basis", "nonlinear_effects", "forward_dynamics", "inverse_dynamics_derivatives",
        "forward_dynamics_derivatives", "inertia_derivatives", "forward_kinematics", "jacobian"}) {
    const std::string fn = f;
    s += "  template <class... A>\n  static auto " + fn + "(A&&... a) -> decltype(" + c.ns + "::" + fn +
         "(std::forward<A>(a)...)) {\n    return " + c.ns + "::" + fn + "(std::forward<A>(a)...);\n  }\n";
  }
  s += "};\n\n" + c.close();
  return s;
}

}  // namespace symoro::codegen::generate
