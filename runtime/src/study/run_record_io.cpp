#include "symoro/study/run_record_io.hpp"

#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/io/atomic_file.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "yaml_vector.hpp"

namespace symoro::study {

namespace {

Eigen::VectorXd vec(const YAML::Node& n) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(n.size()));
  for (std::size_t i = 0; i < n.size(); ++i) v(static_cast<Eigen::Index>(i)) = n[i].as<double>();
  return v;
}

}  // namespace

std::string fingerprint_of(const std::string& text) {
  // FNV-1a, 64 bit: stable across runs and platforms (std::hash is not).
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

std::string run_record_text(const RunRecord& r, const std::string& fingerprint) {
  YAML::Emitter y;
  y.SetDoublePrecision(17);
  if (r.failed) {  // the reason only: a rerun with the same inputs fails the same way
    y << YAML::BeginMap;
    y << YAML::Key << "format" << YAML::Value << "symoro-identification-run 1";
    y << YAML::Key << "fingerprint" << YAML::Value << fingerprint;
    y << YAML::Key << "trajectory" << YAML::Value << r.trajectory;
    y << YAML::Key << "interval" << YAML::Value << r.interval;
    y << YAML::Key << "failed" << YAML::Value << true;
    y << YAML::Key << "failure" << YAML::Value << r.failure;
    y << YAML::EndMap;
    return std::string(y.c_str()) + "\n";
  }
  y << YAML::BeginMap;
  y << YAML::Key << "format" << YAML::Value << "symoro-identification-run 1";
  y << YAML::Key << "fingerprint" << YAML::Value << fingerprint;
  y << YAML::Key << "trajectory" << YAML::Value << r.trajectory;
  y << YAML::Key << "interval" << YAML::Value << r.interval;
  y << YAML::Key << "failed" << YAML::Value << r.failed;
  y << YAML::Key << "failure" << YAML::Value << r.failure;
  y << YAML::Key << "clie_ran" << YAML::Value << r.clie_ran;
  y << YAML::Key << "samples" << YAML::Value << r.samples;
  if (r.edge_samples > 0) y << YAML::Key << "edge_samples" << YAML::Value << r.edge_samples;
  y << YAML::Key << "kappa" << YAML::Value << r.kappa;
  y << YAML::Key << "kappa_scaled" << YAML::Value << r.kappa_scaled;
  y << YAML::Key << "log_det_scaled" << YAML::Value << r.log_det_scaled;
  y << YAML::Key << "weakest" << YAML::Value << r.weakest;
  detail::put_vector(y, "phi_ols", r.phi_ols);
  detail::put_vector(y, "std_ols", r.std_ols);
  y << YAML::Key << "residual_rms" << YAML::Value << r.residual_rms;
  y << YAML::Key << "weighted" << YAML::Value << r.weighted;
  y << YAML::Key << "ols_lambda_min" << YAML::Value << r.ols_lambda_min;
  detail::put_vector(y, "ols_worst_pose", r.ols_worst_pose);
  y << YAML::Key << "ols_pd" << YAML::Value << r.ols_pd;
  y << YAML::Key << "route" << YAML::Value << r.route;
  y << YAML::Key << "eps" << YAML::Value << r.eps;
  y << YAML::Key << "sdp_feasible" << YAML::Value << r.sdp_feasible;
  detail::put_vector(y, "phi_sdp", r.phi_sdp);
  detail::put_vector(y, "phi_clie", r.phi_clie);
  y << YAML::Key << "clie_success" << YAML::Value << r.clie_success;
  y << YAML::Key << "clie_termination" << YAML::Value << r.clie_termination;
  y << YAML::Key << "clie_cost_initial" << YAML::Value << r.clie_cost_initial;
  y << YAML::Key << "clie_cost_final" << YAML::Value << r.clie_cost_final;
  y << YAML::Key << "clie_iterations" << YAML::Value << r.clie_iterations;
  detail::put_vector(y, "clie_rms", r.clie_rms);
  y << YAML::Key << "clie_lambda_min" << YAML::Value << r.clie_lambda_min;
  y << YAML::Key << "clie_pd" << YAML::Value << r.clie_pd;
  if (r.physical) {  // the physical path only: the PD path's records are as they were
    y << YAML::Key << "ols_consistent" << YAML::Value << r.ols_consistent;
    y << YAML::Key << "ols_consistency" << YAML::Value << r.ols_consistency;
    y << YAML::Key << "clie_consistent" << YAML::Value << r.clie_consistent;
    y << YAML::Key << "clie_consistency" << YAML::Value << r.clie_consistency;
  }
  y << YAML::Key << "t_ols" << YAML::Value << r.t_ols;
  y << YAML::Key << "t_audit" << YAML::Value << r.t_audit;
  y << YAML::Key << "t_sdp" << YAML::Value << r.t_sdp;
  y << YAML::Key << "t_clie" << YAML::Value << r.t_clie;
  y << YAML::EndMap;
  return std::string(y.c_str()) + "\n";
}

void save_run(const RunRecord& r, const std::string& fingerprint, const std::filesystem::path& file) {
  io::write_file_atomically(file, run_record_text(r, fingerprint));
}

namespace {

RunRecord parse(const YAML::Node& n) {
  RunRecord r;
  r.trajectory = n["trajectory"].as<std::string>();
  r.interval = n["interval"].as<double>();
  r.failed = n["failed"] ? n["failed"].as<bool>() : false;
  r.failure = n["failure"] ? n["failure"].as<std::string>() : "";
  r.clie_ran = n["clie_ran"] ? n["clie_ran"].as<bool>() : true;
  if (r.failed) return r;  // nothing else was computed
  r.samples = n["samples"].as<int>();
  r.edge_samples = n["edge_samples"] ? n["edge_samples"].as<int>() : 0;
  r.kappa = n["kappa"].as<double>();
  r.kappa_scaled = n["kappa_scaled"].as<double>();
  r.log_det_scaled = n["log_det_scaled"].as<double>();
  r.weakest = n["weakest"].as<std::string>();
  r.phi_ols = vec(n["phi_ols"]);
  r.std_ols = vec(n["std_ols"]);
  r.residual_rms = n["residual_rms"].as<double>();
  r.weighted = n["weighted"].as<bool>();
  r.ols_lambda_min = n["ols_lambda_min"].as<double>();
  r.ols_worst_pose = vec(n["ols_worst_pose"]);
  r.ols_pd = n["ols_pd"].as<bool>();
  r.route = n["route"].as<std::string>();
  r.eps = n["eps"].as<double>();
  r.sdp_feasible = n["sdp_feasible"].as<bool>();
  r.phi_sdp = vec(n["phi_sdp"]);
  r.phi_clie = vec(n["phi_clie"]);
  r.clie_success = n["clie_success"].as<bool>();
  r.clie_termination = n["clie_termination"].as<std::string>();
  r.clie_cost_initial = n["clie_cost_initial"].as<double>();
  r.clie_cost_final = n["clie_cost_final"].as<double>();
  r.clie_iterations = n["clie_iterations"].as<int>();
  r.clie_rms = vec(n["clie_rms"]);
  r.clie_lambda_min = n["clie_lambda_min"].as<double>();
  r.clie_pd = n["clie_pd"].as<bool>();
  if (n["ols_consistent"]) {
    r.physical = true;
    r.ols_consistent = n["ols_consistent"].as<bool>();
    r.ols_consistency = n["ols_consistency"].as<double>();
    r.clie_consistent = n["clie_consistent"].as<bool>();
    r.clie_consistency = n["clie_consistency"].as<double>();
  }
  r.t_ols = n["t_ols"].as<double>();
  r.t_audit = n["t_audit"].as<double>();
  r.t_sdp = n["t_sdp"].as<double>();
  r.t_clie = n["t_clie"].as<double>();
  return r;
}

}  // namespace

RunRecord run_record_from_text(const std::string& text) {
  try {
    return parse(io::load_yaml_text(text, "a run record"));
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("a run record that does not parse: ") + e.what());
  }
}

std::optional<RunRecord> load_run(const std::filesystem::path& file, const std::string& fingerprint) {
  if (!std::filesystem::exists(file)) return std::nullopt;
  try {
    const YAML::Node n = io::load_yaml_file(file);
    if (n["fingerprint"].as<std::string>() != fingerprint) return std::nullopt;
    if (!n["failed"].as<bool>(false) && !n["log_det_scaled"])
      return std::nullopt;  // a record before issue 29: done again
    return parse(n);
  } catch (const YAML::Exception&) {
    return std::nullopt;  // unreadable: the run is done again
  }
}

}  // namespace symoro::study
