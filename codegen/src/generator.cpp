// generate_robot: the robot's full model and each variant of robot.yaml, every one as the same
// set of headers (generate/headers.hpp, one emitter per kind), then the robot's own headers. The
// models are written in this order, one after the other, because each adds nodes to the robot's
// graph and the generated text follows their numbering.
#include "symoro/codegen/generator.hpp"

#include "generate/headers.hpp"
#include "generate/variant_parameters.hpp"
#include "symoro/codegen/source_digest.hpp"

namespace symoro::codegen {

namespace {

using generate::ModelContext;

// The headers of one model under <robot>/include/<its folder>/, and its summary.
void write_model(ModelContext& c, Generation& out) {
  ModelSummary summary;
  summary.name = c.variant.empty() ? c.r.name : c.r.name + "::" + c.variant;
  summary.description = c.description;
  for (int p : c.identified) summary.identified.push_back(c.r.base[p]);
  for (const auto& e : c.effects) {
    summary.identified.push_back({e.name, e.family, e.joint, e.unit});
    summary.effects.emplace_back(e.name, effect_term_text(e, c.r.q[e.joint - 1], c.r.qd[e.joint - 1]));
  }
  summary.fixed = c.fixed;
  c.summary = &summary;
  auto add = [&](const std::string& file, const std::string& text) {
    out.files.push_back({c.r.name + "/include/" + c.dir + "/" + file, text});
  };
  add("model.hpp", generate::model_header(c));
  add("base_parameters.hpp", generate::base_parameters_header(c));
  add("regressor.hpp", generate::regressor_header(c));
  add("inverse_dynamics.hpp", generate::inverse_dynamics_header(c));
  add("inertia.hpp", generate::inertia_header(c));
  add("nonlinear_effects.hpp", generate::nonlinear_effects_header(c));
  add("forward_dynamics.hpp", generate::forward_dynamics_header(c));
  add("inverse_dynamics_derivatives.hpp", generate::inverse_dynamics_derivatives_header(c));
  add("forward_dynamics_derivatives.hpp", generate::forward_dynamics_derivatives_header(c));
  add("inertia_derivatives.hpp", generate::inertia_derivatives_header(c));
  add("forward_kinematics.hpp", generate::forward_kinematics_header(c));
  add("jacobian.hpp", generate::jacobian_header(c));
  add("all.hpp", generate::all_header(c));
  c.summary = nullptr;
  out.models.push_back(summary);
}

}  // namespace

Generation generate_robot(RobotModel& r) {
  // d DIM / d qdd once for all models: it checks the DIM before any header is written.
  const generate::DimDerivatives dd = generate::dim_derivatives(r);

  Generation out;
  ModelContext full(r, dd, "", r.spec.description, {});
  write_model(full, out);
  std::vector<ModelContext> variants;
  for (const auto& v : r.spec.variants) {
    // One expression, as before the split: the order in which the compiler evaluates the two
    // resolutions decides which of their errors a variant with both reports.
    variants.emplace_back(r, dd, v.name, v.description, generate::resolve_fixed(r, v), generate::resolve_effects(r, v));
    write_model(variants.back(), out);
  }

  out.files.push_back({r.name + "/include/symoro/" + r.name + ".hpp", generate::robot_header(r, full, variants)});
  out.files.push_back({r.name + "/include/symoro/" + r.name + "/source.hpp", source_digest_header(r)});
  return out;
}

}  // namespace symoro::codegen
