// model.hpp: what generic code and tools read of a model without its functions (sizes, the
// parameter tables, joints, frames, gravity), as constexpr data of symoro/model_info.hpp's types.
#include <sstream>

#include "headers.hpp"
#include "symoro/codegen/emitter.hpp"

namespace symoro::codegen::generate {

namespace {

// A C++ string literal's content on one line.
std::string escape(const std::string& in) {
  std::string out;
  for (char c : in) {
    if (c == '"' || c == '\\') out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out;
}

// The model's names and sizes: nq, np, ns, nf (and ne with effects).
void write_names_and_sizes(const ModelContext& c, std::ostringstream& s) {
  s << "inline constexpr const char* robot_name = " << quoted(c.r.name) << ";\n";
  s << "// The variant's name; empty for the robot's full model.\n";
  s << "inline constexpr const char* variant_name = " << quoted(c.variant) << ";\n";
  s << "inline constexpr const char* description = " << quoted(escape(c.description)) << ";\n";
  s << "inline constexpr int nq = " << c.r.n << ";  // joints\n";
  if (c.ne() == 0) {
    s << "inline constexpr int np = " << c.np() << ";  // identified base parameters\n";
  } else {
    s << "inline constexpr int np = " << c.np()
      << ";  // identified parameters: base parameters, then effect parameters\n";
  }
  s << "inline constexpr int ns = " << c.r.standard.size() + c.effects.size() << ";  // standard parameters\n";
  s << "inline constexpr int nf = " << c.r.frames.size() << ";  // frames\n";
  if (c.ne() > 0)
    s << "inline constexpr int ne = " << c.ne()
      << ";  // effect parameters (robot.yaml effects): the last ne entries of phi and of s\n";
  s << "\n";
}

// The parameter tables: identified, fixed, their parent indices, standard and effect parameters,
// and the param:: indices into phi.
void write_parameter_tables(const ModelContext& c, std::ostringstream& s) {
  s << "// Identified base parameters: the columns of the regressor and the entries of phi.\n";
  s << "inline constexpr std::array<ParameterInfo, np> parameters = {{\n";
  for (int p : c.identified) {
    const auto& b = c.r.base[p];
    s << "    {" << quoted(b.name) << ", " << quoted(b.family) << ", " << b.joint << ", " << quoted(b.unit) << "},\n";
  }
  for (const auto& e : c.effects)
    s << "    {" << quoted(e.name) << ", " << quoted(e.family) << ", " << e.joint << ", " << quoted(e.unit) << "},\n";
  s << "}};\n\n";
  s << "// Indices into phi by name: phi[param::" << (c.identified.empty() ? "X" : c.r.base[c.identified[0]].name)
    << "].\n";
  s << "namespace param {\nenum : int {\n";
  const auto names = c.identified_names();
  for (std::size_t i = 0; i < names.size(); ++i) s << "  " << names[i] << " = " << i << ",\n";
  s << "};\n}  // namespace param\n\n";
  s << "// Base parameters fixed at generation time (robot.yaml variants).\n";
  s << "inline constexpr std::array<FixedParameter, " << c.fixed_index.size() << "> fixed_parameters = {{\n";
  for (const auto& [p, v] : c.fixed_index) s << "    {" << quoted(c.r.base[p].name) << ", " << cpp_literal(v) << "},\n";
  s << "}};\n\n";
  s << "// Index of each identified parameter in the robot's full parameter vector"
    << (c.ne() > 0 ? " (-1 for the effect\n// parameters, which the full model does not have).\n" : ".\n");
  s << "inline constexpr std::array<int, np> parent_index = {{";
  for (std::size_t i = 0; i < c.identified.size(); ++i) s << (i ? ", " : "") << c.identified[i];
  for (std::size_t i = 0; i < c.effects.size(); ++i) s << (c.identified.empty() && i == 0 ? "" : ", ") << -1;
  s << "}};\n\n";
  if (c.ne() == 0) {
    s << "// Standard parameters (the .par's symbols): the argument of base_from_standard.\n";
  } else {
    s << "// Standard parameters (the .par's symbols, then the effect parameters): the argument of\n"
         "// base_from_standard.\n";
  }
  s << "inline constexpr std::array<StandardParameterInfo, ns> standard_parameters = {{\n";
  for (const auto& p : c.r.standard)
    s << "    {" << quoted(p.name) << ", " << quoted(p.family) << ", " << p.joint << "},\n";
  for (const auto& e : c.effects)
    s << "    {" << quoted(e.name) << ", " << quoted(e.family) << ", " << e.joint << "},\n";
  s << "}};\n\n";
  if (c.ne() > 0) {
    s << "// Effect parameters (robot.yaml effects), the last ne entries of phi: name, family, joint,\n"
         "// order, velocity. Each adds phi * term to its joint's torque: OFF 1, FST sign(qd) exp(-(qd /\n"
         "// velocity)^2), FVA |qd|, HS sin(order q), HC cos(order q).\n";
    s << "inline constexpr std::array<EffectParameterInfo, ne> effect_parameters = {{\n";
    for (const auto& e : c.effects)
      s << "    {" << quoted(e.name) << ", " << quoted(e.family) << ", " << e.joint << ", " << e.order << ", "
        << cpp_literal(e.velocity) << "},\n";
    s << "}};\n\n";
  }
}

// The robot's joints, modified DH frames and gravity.
void write_geometry(const ModelContext& c, std::ostringstream& s) {
  s << "// name, type, position limits, velocity limit, effort limit, PD-audit domain.\n";
  s << "inline constexpr std::array<JointInfo, nq> joints = {{\n";
  for (int j = 0; j < c.r.n; ++j) {
    const auto& js = c.r.spec.joints[j];
    s << "    {" << quoted(js.name) << ", "
      << (c.r.frames[j].sigma == 1 ? "JointType::Prismatic" : "JointType::Revolute") << ", " << cpp_literal(js.lower)
      << ", " << cpp_literal(js.upper) << ", " << cpp_literal(js.velocity) << ", " << cpp_literal(js.effort) << ", "
      << cpp_literal(js.audit_lower) << ", " << cpp_literal(js.audit_upper) << "},\n";
  }
  s << "}};\n\n";
  s << "// Modified DH frames: ant, sigma, mu, gamma, b, alpha, d, theta, r.\n";
  s << "inline constexpr std::array<FrameInfo, nf> frames = {{\n";
  for (const auto& f : c.r.frames)
    s << "    {" << f.ant << ", " << f.sigma << ", " << f.mu << ", " << cpp_literal(f.gamma) << ", " << cpp_literal(f.b)
      << ", " << cpp_literal(f.alpha) << ", " << cpp_literal(f.d) << ", " << cpp_literal(f.theta) << ", "
      << cpp_literal(f.r) << "},\n";
  s << "}};\n\n";
  s << "// Gravity acceleration in frame 0 (m/s^2).\n";
  s << "inline constexpr std::array<double, 3> gravity = {{" << cpp_literal(c.r.gravity[0]) << ", "
    << cpp_literal(c.r.gravity[1]) << ", " << cpp_literal(c.r.gravity[2]) << "}};\n\n";
}

}  // namespace

std::string model_header(ModelContext& c) {
  std::ostringstream s;
  s << c.banner("Model description: sizes, parameters, joints, geometry.");
  s << "#include <array>\n\n#include \"symoro/model_info.hpp\"\n\n" << c.open();
  write_names_and_sizes(c, s);
  write_parameter_tables(c, s);
  write_geometry(c, s);
  s << c.close();
  return s.str();
}

}  // namespace symoro::codegen::generate
