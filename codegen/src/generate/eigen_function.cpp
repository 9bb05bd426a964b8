// The form of every generated model function: a template over Eigen inputs writing into `out`
// (resized and zeroed, then the nonzero entries), and a value-returning overload whose scalar
// is the inputs' promoted scalar (so Jets, autodiff types and double mix).
#include "model_context.hpp"
#include "symoro/codegen/emitter.hpp"

namespace symoro::codegen::generate {

std::string ModelContext::function(const std::string& doc, const std::string& name, const std::vector<Input>& in,
                                   const Output& o) {
  std::map<std::string, std::string> symbols;
  std::vector<Assignment> assignments;
  std::vector<NodeId> roots;
  for (const auto& i : in)
    for (std::size_t k = 0; k < i.symbols.size(); ++k)
      symbols[i.symbols[k]] = i.name + "[" + str(static_cast<int>(k)) + "]";
  for (std::size_t rr = 0; rr < o.entries.size(); ++rr)
    for (std::size_t c = 0; c < o.entries[rr].size(); ++c) {
      const NodeId v = o.entries[rr][c];
      roots.push_back(v);
      if (!g.is_constant(v, 0.0))
        assignments.push_back({o.name + "(" + str(static_cast<int>(rr)) + ", " + str(static_cast<int>(c)) + ")", v});
    }
  summary->functions.push_back({name, count_operations(g, roots)});

  std::string params, args, types, value_types, sizes;
  for (const auto& i : in) {
    types += "class " + i.type + ", ";
    value_types += (value_types.empty() ? "" : ", ") + std::string("class ") + i.type;
    params += "const Eigen::MatrixBase<" + i.type + ">& " + i.name + ", ";
    args += i.name + ", ";
    sizes += "  eigen_assert(" + i.name + ".size() == " + str(static_cast<int>(i.symbols.size())) + ");\n";
  }
  const std::string body = emit_body(g, symbols, assignments, "  ");
  std::string s = doc;
  s += "template <" + types + "class Out>\n";
  s += "inline void " + name + "(" + params + "const Eigen::MatrixBase<Out>& out) {\n";
  if (!body.empty()) s += "  using Scalar = typename Out::Scalar;\n";  // unused when all outputs are 0
  s += usings(roots);
  s += sizes;
  for (const auto& i : in) s += "  static_cast<void>(" + i.name + ");\n";
  s += "  Eigen::MatrixBase<Out>& " + o.name + " = const_cast<Eigen::MatrixBase<Out>&>(out);\n";
  s += "  " + o.name + ".derived().resize(" + o.rows + ", " + o.cols + ");\n";
  s += "  " + o.name + ".setZero();\n";
  s += body;
  s += "}\n\n";

  std::string promoted;
  for (const auto& i : in) promoted += (promoted.empty() ? "" : ", ") + std::string("typename ") + i.type + "::Scalar";
  const std::string ret = "Eigen::Matrix<::symoro::promote_t<" + promoted + ">, " + o.rows + ", " + o.cols + ">";
  s += "template <" + value_types + ">\n";
  s += "inline " + ret + " " + name + "(" + params.substr(0, params.size() - 2) + ") {\n";
  s += "  " + ret + " " + o.name + ";\n";
  s += "  " + name + "(" + args + o.name + ");\n";
  s += "  return " + o.name + ";\n}\n\n";
  return s;
}

}  // namespace symoro::codegen::generate
