// base_parameters.hpp: the identified parameters from the standard ones (regp.txt), and the
// maps between a variant's phi and the robot's full one (fixed entries filled in or dropped).
#include "headers.hpp"
#include "symoro/codegen/emitter.hpp"

namespace symoro::codegen::generate {

std::string base_parameters_header(ModelContext& c) {
  std::vector<NodeId> rows;
  for (int p : c.identified) rows.push_back(c.r.base_from_standard[p]);
  for (const auto& e : c.effects) rows.push_back(c.g.symbol(e.name));  // identical in s and phi
  std::string s = c.banner("Base parameters from standard parameters (regp.txt), and to/from the full model.");
  s += "#include <Eigen/Core>\n\n#include \"symoro/scalar.hpp\"\n" + c.include_self("model.hpp");
  if (!c.variant.empty()) s += "#include \"symoro/" + c.r.name + "/model.hpp\"\n";
  s += "\n" + c.open();
  s += c.function(
      "// The identified base parameters of a standard parameter vector s (size ns, in the order\n"
      "// of standard_parameters): phi = base_from_standard(s). Linear in s.\n",
      "base_from_standard", {{"S", "s", c.standard_names()}}, {"phi", "np", "1", column(rows)});
  const std::string parent_np = "::symoro::" + c.r.name + "::np";
  s += "// The robot's full base parameter vector from this model's phi, with fixed entries filled in.\n";
  if (c.ne() > 0) s += "// The effect parameters (the last ne of phi) have no place in it and are dropped.\n";
  const std::string loop_end = c.ne() > 0 ? "np - ne" : "np";
  s += "template <class Phi>\n";
  s += "inline Eigen::Matrix<typename Phi::Scalar, " + parent_np +
       ", 1> to_parent(const Eigen::MatrixBase<Phi>& phi) {\n";
  s += "  using Scalar = typename Phi::Scalar;\n  eigen_assert(phi.size() == np);\n";
  s += "  Eigen::Matrix<Scalar, " + parent_np + ", 1> full;\n";
  s += "  for (int i = 0; i < " + loop_end + "; ++i) full[parent_index[static_cast<std::size_t>(i)]] = phi[i];\n";
  for (const auto& [p, v] : c.fixed_index)
    s += "  full[" + str(p) + "] = Scalar(" + cpp_literal(v) + ");  // " + c.r.base[p].name + "\n";
  s += "  return full;\n}\n\n";
  s += "// This model's phi from the robot's full base parameter vector (fixed entries are dropped";
  s += c.ne() > 0 ? ";\n// the effect parameters, which it does not have, are 0).\n" : ").\n";
  s += "template <class Full>\n";
  s += "inline Eigen::Matrix<typename Full::Scalar, np, 1> from_parent(const Eigen::MatrixBase<Full>& full) {\n";
  s += "  eigen_assert(full.size() == " + parent_np + ");\n";
  s += "  Eigen::Matrix<typename Full::Scalar, np, 1> phi;\n";
  s += "  for (int i = 0; i < " + loop_end + "; ++i) phi[i] = full[parent_index[static_cast<std::size_t>(i)]];\n";
  if (c.ne() > 0) s += "  for (int i = np - ne; i < np; ++i) phi[i] = typename Full::Scalar(0);\n";
  s += "  return phi;\n}\n\n";
  s += c.close();
  return s;
}

}  // namespace symoro::codegen::generate
