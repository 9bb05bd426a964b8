// One generated model (the robot's full model, or a variant of robot.yaml) as the header
// emitters see it: which base parameters it identifies and which it fixes, its effect
// parameters, its namespace and include folder, and the helpers every header shares (banner,
// namespace, the generated function's form, the model's expressions with its fixed values and
// effects). The emitters (headers.hpp) take it by reference and append to its summary.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "symoro/codegen/effects.hpp"
#include "symoro/codegen/generator.hpp"

namespace symoro::codegen::generate {

// Derivatives of every DIM entry with respect to every joint acceleration, with QP = QDP = 0:
// [k][j][p] = d DG{j}{p} / d QDP{k}, the entry (j, k) of the inertia basis matrix of p.
using DimDerivatives = std::vector<std::vector<std::vector<NodeId>>>;

// A function input: a template parameter, an argument name and the graph symbols it carries.
struct Input {
  std::string type;                  // template parameter
  std::string name;                  // argument
  std::vector<std::string> symbols;  // symbol k is read as name[k]
};

// An Eigen output of the function and its entries.
struct Output {
  std::string name;                          // local reference inside the function, e.g. "W"
  std::string rows, cols;                    // C++ constants
  std::vector<std::vector<NodeId>> entries;  // [row][col]
};

std::string str(int v);
std::string quoted(const std::string& s);
// A one-column Output's entries.
std::vector<std::vector<NodeId>> column(const std::vector<NodeId>& v);

class ModelContext {
 public:
  // `variant` is empty for the full model; `fixed` are the base parameters it fixes, in
  // parameter order. Builds the effect terms on the graph, so contexts are made in output order.
  ModelContext(RobotModel& robot, const DimDerivatives& dd, std::string variant, std::string description,
               std::vector<std::pair<std::string, double>> fixed, std::vector<EffectParameter> effects = {});

  // The header's first lines, the model's namespace around its body, and an include of a header
  // of this model.
  std::string banner(const std::string& what) const;
  std::string open() const { return "namespace " + ns + " {\n\n"; }
  std::string close() const { return "}  // namespace " + ns + "\n"; }
  std::string include_self(const std::string& file) const { return "#include \"" + dir + "/" + file + "\"\n"; }
  // The includes of a header of generated functions.
  std::string kinematic_includes() const;

  std::string all_include() const { return dir + "/all.hpp"; }
  std::string model_type() const { return "::" + ns + "::Model"; }

  // The entries of phi: the identified base parameters, then the effect parameters.
  std::vector<std::string> identified_names() const;
  // The entries of s: the .par's standard parameters, then the effect parameters.
  std::vector<std::string> standard_names() const;
  bool is_identified(const std::string& name) const;
  int np() const { return static_cast<int>(identified.size() + effects.size()); }
  int ne() const { return static_cast<int>(effects.size()); }

  Input q_in() const { return {"Q", "q", r.q}; }
  Input qd_in() const { return {"QD", "qd", r.qd}; }
  Input qdd_in() const { return {"QDD", "qdd", r.qdd}; }
  Input tau_in() const { return {"Tau", "tau", r.tau}; }
  Input phi_in() const { return {"Phi", "phi", identified_names()}; }

  // The robot's expressions with this model's fixed values substituted.
  std::vector<NodeId> specialize(const std::vector<NodeId>& roots);
  // sum of phi_e * term_e over the effect parameters of joint j (0-based), 0 when it has none.
  NodeId effect_torque(int j);
  std::vector<NodeId> plus_effects(std::vector<NodeId> tau);
  // [joint][identified parameter]: the regressor's entries, effect terms last.
  std::vector<std::vector<NodeId>> regressor_entries();
  // M(q; phi): the derivative of the factored Newton-Euler torque (idm.txt) with respect to qdd,
  // far cheaper than summing the basis.
  std::vector<std::vector<NodeId>> inertia_entries();

  std::string usings(const std::vector<NodeId>& roots) const;
  // The in-place function and its value-returning form (eigen_function.cpp); its operation
  // count goes to the summary.
  std::string function(const std::string& doc, const std::string& name, const std::vector<Input>& in, const Output& o);

  RobotModel& r;
  ExprGraph& g;
  const DimDerivatives& dd;
  std::string variant, description;
  std::vector<std::pair<std::string, double>> fixed;
  std::vector<EffectParameter> effects;
  std::vector<NodeId> effect_terms;                 // per effect parameter: its term on its joint's row
  std::vector<int> identified;                      // indices into r.base
  std::vector<std::pair<int, double>> fixed_index;  // index into r.base, value
  std::map<std::string, NodeId> replacements;       // fixed base parameter -> its constant
  std::string ns, dir;                              // "symoro::<robot>[::<variant>]", "symoro/<robot>[/<variant>]"
  ModelSummary* summary = nullptr;                  // set while the model's headers are written
};

}  // namespace symoro::codegen::generate
