// Payload identification from Python (docs/payload.md): symoro.identify_payload, as dynid
// payload, returning the payload, its standard deviations and the controllers' forms as a dict.
#include <cmath>
#include <filesystem>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/payload/payload_formats.hpp"
#include "symoro/payload/payload_identification.hpp"

namespace symoro::python {

std::shared_ptr<const identify::IdentificationModel> identification_of(py::handle model);
std::optional<std::filesystem::path> robot_dir_of(py::handle model, const std::optional<std::filesystem::path>& given);
Eigen::VectorXd parameters_of(const identify::IdentificationModel& model, py::handle params,
                              const std::optional<std::filesystem::path>& robot_dir);
// The logged torque's delay (ms) a fit on top of `params` takes: the one given, else a parameters
// file's torque_delay_ms, else 0 (results_binding.cpp).
double torque_delay_of(py::handle params, std::optional<double> given_ms);

namespace {

std::vector<io::Log> logs_of(const std::vector<std::filesystem::path>& inputs, const identify::ModelDescription& d,
                             int trial) {
  std::vector<io::Log> logs;
  for (const auto& input : inputs)
    for (auto& l : io::read_input_logs(input, d.robot, d.nq, trial)) logs.push_back(std::move(l.log));
  if (logs.empty()) throw py::value_error(fmt::format("no run of trial {} in the inputs", trial));
  return logs;
}

}  // namespace

void bind_payload(py::module_& m) {
  m.def(
      "identify_payload",
      [](py::handle model, py::handle params, const std::vector<std::filesystem::path>& inputs, py::handle full,
         std::optional<double> mass, double interval_ms, std::optional<double> torque_delay_given, int trial,
         const std::optional<std::filesystem::path>& robot_dir_given, const std::string& instruments,
         const std::vector<std::filesystem::path>& tare_inputs) {
        if (instruments != "none" && instruments != "reference")
          throw py::value_error(fmt::format("instruments '{}': 'none' or 'reference'", instruments));
        if (!(std::isfinite(interval_ms) && interval_ms >= 1 && interval_ms <= 10000))
          throw py::value_error(fmt::format("interval_ms {}: must be from 1 to 10000", interval_ms));
        // The arm's timing unless told otherwise: a parameters file's torque_delay_ms (its rotor
        // inertias carry the logged torque's timing, docs/payload.md), else 0.
        const double torque_delay_ms = torque_delay_of(params, torque_delay_given);
        if (!(std::isfinite(torque_delay_ms) && torque_delay_ms >= -1000 && torque_delay_ms <= 1000))
          throw py::value_error(fmt::format("torque_delay_ms {}: must be from -1000 to 1000", torque_delay_ms));
        if (mass && !(std::isfinite(*mass) && *mass > 0 && *mass <= 1e4))
          throw py::value_error(fmt::format("mass {}: must be above 0 and at most 1e4 kg", *mass));
        if (trial < 1) throw py::value_error(fmt::format("trial {}: must be 1 or more", trial));
        const auto arm = identification_of(model);
        const auto whole = full.is_none() ? arm : identification_of(full);
        const identify::ModelDescription& d = arm->description();
        if (!whole->description().variant.empty())
          throw py::value_error(fmt::format(
              "full: the payload's regressor is the robot's full model; give full=<robot>.full (the {} model is "
              "a variant)",
              whole->description().variant));
        const std::optional<std::filesystem::path> robot_dir = robot_dir_of(model, robot_dir_given);
        const Eigen::VectorXd phi = parameters_of(*arm, params, robot_dir);
        const std::vector<io::Log> logs = logs_of(inputs, d, trial);
        const std::vector<io::Log> tare = tare_inputs.empty() ? std::vector<io::Log>{} : logs_of(tare_inputs, d, trial);
        payload::PayloadOptions o;
        o.interval = interval_ms / 1000;
        o.torque_delay = torque_delay_ms / 1000;
        o.mass = mass;
        o.reference_instruments = instruments == "reference";
        const payload::PayloadLink link = payload::payload_link(*whole);
        std::string flange = fmt::format("frame {}", link.link);
        if (robot_dir)
          flange = payload::robot_flange((*robot_dir / "robot.yaml").string(), link.link,
                                         static_cast<int>(d.frames.size()), o.flange_in_link);
        payload::PayloadEstimate e;
        {
          py::gil_scoped_release release;
          e = payload::identify_payload(logs, tare, *arm, phi, *whole, o);
        }
        py::dict r;
        r["mass"] = e.payload.mass;
        r["com"] = Eigen::VectorXd(e.payload.com);
        r["inertia"] = Eigen::MatrixXd(e.payload.inertia);
        r["mass_std"] = e.mass_std;
        r["com_std"] = Eigen::VectorXd(e.com_std);
        r["inertia_std"] = Eigen::VectorXd(e.inertia_std);
        r["flange"] = flange;
        r["link"] = e.link;
        r["standard"] = Eigen::VectorXd(e.standard);
        r["least_squares"] = Eigen::VectorXd(e.least_squares);
        r["covariance"] = Eigen::MatrixXd(e.covariance);
        r["known_mass"] = e.known_mass;
        r["projected"] = e.projected;
        r["margin"] = e.margin;
        r["status"] = e.status;
        r["samples"] = e.samples;
        r["torque_delay_ms"] = torque_delay_ms;
        r["tare"] = Eigen::VectorXd(e.tare);
        r["tare_samples"] = e.tare_samples;
        r["lags"] = e.lags;
        r["condition"] = e.condition;
        r["rms_without"] = e.rms_without;
        r["rms_with"] = e.rms_with;
        r["urdf"] =
            payload::payload_urdf(e.payload, flange.rfind("frame ", 0) == 0 ? "link" + std::to_string(e.link) : flange);
        r["franka"] = payload::franka_load(e.payload);
        r["ur"] = payload::ur_payload(e.payload);
        r["kuka"] = payload::kuka_load(e.payload);
        return r;
      },
      py::arg("model"), py::arg("params"), py::arg("inputs"), py::kw_only(), py::arg("full") = py::none(),
      py::arg("mass") = py::none(), py::arg("interval_ms") = 10.0, py::arg("torque_delay_ms") = py::none(),
      py::arg("trial") = 1, py::arg("robot_dir") = py::none(), py::arg("instruments") = "none",
      py::arg("tare") = std::vector<std::filesystem::path>{},
      "A payload's 10 inertial parameters from logs (or datasets) of the arm carrying it, the arm's parameters "
      "(params: an array or a parameters file of `model`) held: a dict of 'mass', 'com', 'inertia' (about the CoM) "
      "in the flange frame 'flange', their '*_std', 'standard', 'covariance', 'projected', 'status', 'rms_without', "
      "'rms_with', and the 'urdf', 'franka', 'ur' and 'kuka' forms. full: the robot's full model when `model` is a "
      "variant; mass: a known mass (the other 9 identified); torque_delay_ms: the logged torque's delay, by default "
      "the parameters file's (the arm's; 0 for an array), returned as 'torque_delay_ms'; tare: logs or datasets of "
      "the arm without the payload, whose error along the payload's parameters is fitted and taken out (returned as "
      "'tare'). docs/payload.md");
}

}  // namespace symoro::python
