#include "symoro/study/prediction_band.hpp"

#include <cmath>
#include <stdexcept>

#include <boost/math/distributions/normal.hpp>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/identify/hac_covariance.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "symoro/io/yaml_numbers.hpp"

namespace symoro::study {

namespace {

std::string list(const Eigen::VectorXd& v) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) out += (i ? ", " : "") + io::number_text(v(i));
  return out + "]";
}

}  // namespace

PredictionUncertainty prediction_uncertainty(const identify::IdentificationModel& model,
                                             const std::vector<preprocess::Samples>& samples,
                                             const Eigen::VectorXd& phi, const std::string& source) {
  const identify::ModelDescription& d = model.description();
  if (phi.size() != d.np) throw std::invalid_argument("prediction_uncertainty: phi has the wrong size");
  std::vector<Eigen::MatrixXd> Ws;
  std::vector<Eigen::VectorXd> es;
  std::vector<int> segment;
  Eigen::Index rows = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const identify::Regression r = model.stack_regression(samples[i]);
    es.push_back(r.y - r.W * phi);
    Ws.push_back(r.W);
    rows += r.W.rows();
    segment.insert(segment.end(), static_cast<std::size_t>(r.samples), static_cast<int>(i));
  }
  Eigen::MatrixXd W(rows, d.np);
  Eigen::VectorXd e(rows);
  for (std::size_t i = 0, at = 0; i < Ws.size(); at += static_cast<std::size_t>(Ws[i].rows()), ++i) {
    W.middleRows(static_cast<Eigen::Index>(at), Ws[i].rows()) = Ws[i];
    e.segment(static_cast<Eigen::Index>(at), es[i].size()) = es[i];
  }
  PredictionUncertainty u;
  u.model = d.variant;
  for (const auto& p : d.parameters) u.names.push_back(p.name);
  u.samples = static_cast<int>(segment.size());
  if (u.samples * d.nq <= d.np) throw std::invalid_argument("prediction_uncertainty: too few samples");
  const Eigen::Map<const Eigen::MatrixXd> E(e.data(), d.nq, u.samples);
  u.residual = (E.rowwise().squaredNorm() / static_cast<double>(u.samples)).cwiseSqrt();
  u.lags = identify::residual_lags(e, segment, d.nq);
  u.covariance = identify::hac_covariance(W, e, segment, d.nq, u.lags);
  u.covariance = (u.covariance + u.covariance.transpose()) / 2;
  u.source = source;
  return u;
}

Eigen::MatrixXd prediction_band(const identify::IdentificationModel& model, const preprocess::Samples& samples,
                                const PredictionUncertainty& u, double level) {
  const identify::ModelDescription& d = model.description();
  if (!(level > 0 && level < 1)) throw std::invalid_argument(fmt::format("band level {}: from 0 to 1", level));
  if (u.covariance.rows() != d.np || u.residual.size() != d.nq)
    throw std::invalid_argument("prediction_band: the uncertainty is of another model");
  const double z = boost::math::quantile(boost::math::normal(), 0.5 + level / 2);
  const Eigen::MatrixXd W = model.stack_regression(samples).W;
  const Eigen::VectorXd parameters = (W * u.covariance).cwiseProduct(W).rowwise().sum();
  const Eigen::Index K = samples.q.rows();
  Eigen::MatrixXd band(K, d.nq);
  for (Eigen::Index k = 0; k < K; ++k)
    for (int j = 0; j < d.nq; ++j)
      band(k, j) = z * std::sqrt(std::max(parameters(k * d.nq + j), 0.0) + u.residual(j) * u.residual(j));
  return band;
}

BandCoverage band_coverage(const Eigen::MatrixXd& tau, const Eigen::MatrixXd& tau_model, const Eigen::MatrixXd& band) {
  BandCoverage c;
  c.samples = static_cast<int>(tau.rows());
  const Eigen::ArrayXXd inside = ((tau - tau_model).array().abs() <= band.array()).cast<double>();
  c.joint = inside.colwise().mean().transpose();
  c.all = inside.mean();
  return c;
}

std::string uncertainty_yaml(const PredictionUncertainty& u, const std::string& robot) {
  std::string y =
      "# The identified parameters' uncertainty (docs/uncertainty.md): the\n"
      "# covariance of phi (Newey-West: the residual's autocorrelation counted) and the residual's\n"
      "# own level per joint, on the samples named; dynid predict reads it for its bands.\n";
  y += "format: symoro-uncertainty 1\n";
  y += fmt::format("robot: {}\nmodel: {}\n", robot, u.model.empty() ? "full" : u.model);
  y += fmt::format("source: \"{}\"\nsamples: {}\nlags: {}\n", u.source, u.samples, u.lags);
  y += fmt::format("residual: {}  # N m per joint\n", list(u.residual));
  y += "parameters: [";
  for (std::size_t i = 0; i < u.names.size(); ++i) y += (i ? ", " : "") + u.names[i];
  y += "]\ncovariance:  # row by row, in the parameters' order and units\n";
  for (Eigen::Index r = 0; r < u.covariance.rows(); ++r) y += "  - " + list(u.covariance.row(r).transpose()) + "\n";
  return y;
}

PredictionUncertainty read_uncertainty_yaml(const std::string& file, const std::vector<std::string>& names) {
  const YAML::Node root = io::load_yaml_file(file);
  if (!root.IsMap() || !root["format"] || root["format"].as<std::string>() != "symoro-uncertainty 1")
    throw DataError(file, 0, "not an uncertainty file (format: symoro-uncertainty 1; dynid identify writes one)");
  io::check_keys(root,
                 {"format", "robot", "model", "source", "samples", "lags", "residual", "parameters", "covariance"},
                 file, "an uncertainty file");
  PredictionUncertainty u;
  u.model = root["model"] ? root["model"].as<std::string>() : "";
  if (u.model == "full") u.model.clear();
  u.source = root["source"] ? root["source"].as<std::string>() : "";
  u.samples = root["samples"] ? static_cast<int>(io::yaml_number(root["samples"], file, "samples")) : 0;
  u.lags = root["lags"] ? static_cast<int>(io::yaml_number(root["lags"], file, "lags")) : 0;
  const YAML::Node p = root["parameters"];
  if (!p || !p.IsSequence() || p.size() != names.size())
    throw DataError(file, p ? p.Mark().line + 1 : 0,
                    fmt::format("parameters: {} names, the model has {}", p ? p.size() : 0, names.size()));
  for (std::size_t i = 0; i < names.size(); ++i)
    if (p[i].as<std::string>() != names[i])
      throw DataError(file, p[i].Mark().line + 1,
                      fmt::format("parameter {} is {}, the model's is {}", i + 1, p[i].as<std::string>(), names[i]));
  u.names = names;
  const YAML::Node r = root["residual"];
  u.residual = io::yaml_numbers(r, r && r.IsSequence() ? r.size() : 0, file, "residual");
  const YAML::Node c = root["covariance"];
  if (!c || !c.IsSequence() || c.size() != names.size())
    throw DataError(file, c ? c.Mark().line + 1 : 0, fmt::format("covariance: {} rows", names.size()));
  u.covariance.resize(static_cast<Eigen::Index>(names.size()), static_cast<Eigen::Index>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i)
    u.covariance.row(static_cast<Eigen::Index>(i)) =
        io::yaml_numbers(c[i], names.size(), file, "covariance").transpose();
  return u;
}

}  // namespace symoro::study
