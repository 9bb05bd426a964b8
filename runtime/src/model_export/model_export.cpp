#include "symoro/model_export/model_export.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "symoro/io/atomic_file.hpp"

namespace symoro::model_export {

ModelExport export_model(const identify::IdentificationModel& model, const Eigen::VectorXd& phi,
                         const ModelExportOptions& options) {
  const identify::ModelDescription& md = model.description();
  identify::ConsistencyOptions co;
  co.margin = options.margin;
  co.base_metric_root = options.base_metric_root;
  ModelExport e;
  e.consistency = model.consistent_standard_parameters(phi, options.prior, co);
  const identify::ConsistencyResult& r = e.consistency;
  e.nearest = r.status == identify::ConsistencyStatus::NoConsistentSet && options.nearest;
  // Checked here, independently of the solver's own report.
  const Eigen::VectorXd target = model.consistency_target(phi);
  if (r.status == identify::ConsistencyStatus::NoConsistentSet && options.cost)
    e.cost = options.cost(target, r.phi_consistent);
  if (!r.ok() && !e.nearest) {
    std::string why = fmt::format("no URDF written: {} ({})", r.message, to_string(r.status));
    if (r.status == identify::ConsistencyStatus::NoConsistentSet)
      why += fmt::format(
          "; the nearest base vector with a consistent set is {:.4g} away (weighted): --nearest "
          "exports that one{}",
          r.base_distance, e.cost.empty() ? "" : "; " + e.cost);
    throw std::runtime_error(why);
  }
  e.residual = (model.parent_base_from_standard(r.s) - target).cwiseAbs().maxCoeff();

  UrdfDescription& d = e.description;
  d.robot = md.robot;
  d.frames = md.frames;
  d.joints = md.joints;
  d.names = md.standard;
  d.s = r.s;
  const std::string label = md.variant.empty() ? "full" : md.variant;
  d.notes.push_back(fmt::format("Model: {} ({}), {} base parameters. Study: {}{}.", md.robot, label, md.np,
                                std::filesystem::absolute(options.study).lexically_normal().string(),
                                options.accepted ? "" : " (NOT accepted by its final audit)"));
  if (e.nearest)
    d.notes.push_back(
        fmt::format("WARNING: no consistent set reproduces the accepted base parameters ({}); these "
                    "inertials reproduce the nearest base vector that has one, {:.4g} away (weighted): "
                    "max |B s - phi| below is against the accepted vector. {}.",
                    r.message, r.base_distance, e.cost));
  d.notes.push_back(fmt::format(
      "Inertials: the physically consistent standard parameters (pseudo-inertia >= {} I per "
      "link) nearest the prior {} that reproduce {}: max |B s - phi| = {:.3g} (phi the "
      "accepted vector), smallest pseudo-inertia eigenvalue {:.6g}.",
      options.margin, options.prior_what,
      e.nearest ? "the nearest consistent base vector" : "the accepted base parameters", e.residual, r.lambda_min));
  e.header = fmt::format(
      "robot: \"{}\"\nmodel: \"{}\"\nstudy: \"{}\"\nprior: \"{}\"\naccepted: {}\nnearest_consistent_base: {}\n"
      "margin: {}\nlambda_min: {}\nbase_residual: {}\n",
      md.robot, label, options.study, options.prior_what, options.accepted, e.nearest, options.margin, r.lambda_min,
      e.residual);
  return e;
}

ModelExportFiles write_model_export(const ModelExport& e, const std::filesystem::path& urdf,
                                    const std::string& urdf_text) {
  ModelExportFiles f;
  f.urdf = urdf;
  std::filesystem::path stem = urdf;
  stem.replace_extension();
  f.yaml = stem.string() + ".standard.yaml";
  f.csv = stem.string() + ".standard.csv";
  const std::string header =
      "# Physically consistent standard parameters (dynid export) reproducing a study's accepted base\n"
      "# parameters; the URDF " +
      urdf.filename().string() + " holds them but for IA.\n" + e.header;
  if (urdf.has_parent_path()) std::filesystem::create_directories(urdf.parent_path());
  // All three or none: a URDF without its .standard files makes the rerun refuse (a full disk).
  io::write_files_atomically({{f.urdf, urdf_text},
                              {f.yaml, standard_parameters_yaml(e.description, header)},
                              {f.csv, standard_parameters_csv(e.description)}});
  return f;
}

}  // namespace symoro::model_export
