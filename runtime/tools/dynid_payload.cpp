// dynid payload: a payload's (or tool's) 10 inertial parameters from logs of the arm carrying
// it, on top of the arm's identified parameters (held), with standard deviations, physically
// consistent, optionally with a known mass; written as payload.yaml (with Franka's, UR's and
// KUKA's load settings) and payload.urdf (a link on a fixed joint). docs/payload.md.
#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_common.hpp"
#include "dynid_numbers.hpp"
#include "dynid_robots.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "symoro/payload/payload_formats.hpp"
#include "symoro/payload/payload_identification.hpp"
#include "symoro/study/prediction.hpp"

namespace symoro::dynid {

namespace {

namespace fs = std::filesystem;

struct PayloadCliOptions {
  std::string params, model, out;
  std::vector<std::string> inputs, tare;
  double mass = 0;  // kg, > 0: known
  double interval_ms = study::PredictionOptions{}.interval * 1000;
  double torque_delay_ms = 0;
  bool torque_delay_given = false;  // else the arm's (fit_torque_delay)
  int trial = 1;
  bool force = false;
  std::string instruments = "none";
};

void run(const Common& common, const PayloadCliOptions& o) {
  const auto arm = identification_model(common, parameters_model(o.params, o.model));
  const identify::ModelDescription& d = arm->description();
  const Eigen::VectorXd phi =
      parameters_phi(common, robot_model(common, d.variant.empty() ? "full" : d.variant), o.params);
  const auto full = identification_model(common, "full");

  // The runs of --trial in each input (a log or a dataset), named for payload.yaml.
  std::string names;
  const auto runs = [&](const std::vector<std::string>& inputs, const char* what, std::string* named) {
    std::vector<io::Log> out;
    for (const auto& input : inputs)
      for (auto& l : io::read_input_logs(input, d.robot, d.nq, o.trial)) {
        if (named) *named += (named->empty() ? "" : ", ") + (fs::is_directory(input) ? input + ":" + l.name : input);
        out.push_back(std::move(l.log));
      }
    if (out.empty() && !inputs.empty())
      throw UsageError(fmt::format("{}no run of trial {} in {}", what, o.trial, fmt::join(inputs, ", ")));
    return out;
  };
  const std::vector<io::Log> logs = runs(o.inputs, "", &names), tare = runs(o.tare, "--tare: ", nullptr);
  const fs::path out(o.out), yaml_file = out / "payload.yaml", urdf_file = out / "payload.urdf";
  for (const auto& f : {yaml_file, urdf_file})
    if (fs::exists(f) && !o.force)
      throw UsageError(f.string() + " exists: dynid payload does not overwrite it; choose another -o, or --force");

  payload::PayloadOptions po;
  po.interval = o.interval_ms / 1000;
  const FitTiming timing =
      fit_torque_delay(o.params, o.torque_delay_given ? std::optional<double>(o.torque_delay_ms) : std::nullopt);
  po.torque_delay = timing.torque_delay_ms / 1000;
  if (o.mass > 0) po.mass = o.mass;
  po.reference_instruments = o.instruments == "reference";
  const payload::PayloadLink link = payload::payload_link(*full);
  const std::string flange = payload::robot_flange((common.robot_dir() / "robot.yaml").string(), link.link,
                                                   static_cast<int>(d.frames.size()), po.flange_in_link);
  payload::PayloadEstimate e;
  try {
    e = payload::identify_payload(logs, tare, *arm, phi, *full, po);
  } catch (const std::invalid_argument& err) {
    throw UsageError(err.what());
  }
  const payload::PayloadInertial& p = e.payload;
  fmt::print("{}: payload on link {} ({} model's parameters {} held), in the flange frame {}:\n", common.robot, e.link,
             d.variant.empty() ? "full" : d.variant, o.params, flange);
  fmt::print("  mass    {:.5g} kg{}\n", p.mass, e.known_mass ? " (given)" : fmt::format(" +- {:.2g}", e.mass_std));
  fmt::print("  com     [{:.1f}, {:.1f}, {:.1f}] mm +- [{:.2g}, {:.2g}, {:.2g}]\n", p.com.x() * 1000, p.com.y() * 1000,
             p.com.z() * 1000, e.com_std.x() * 1000, e.com_std.y() * 1000, e.com_std.z() * 1000);
  fmt::print("  inertia about the CoM: Ixx {:.4g} Iyy {:.4g} Izz {:.4g} Ixy {:.3g} Ixz {:.3g} Iyz {:.3g} kg m^2\n",
             p.inertia(0, 0), p.inertia(1, 1), p.inertia(2, 2), p.inertia(0, 1), p.inertia(0, 2), p.inertia(1, 2));
  fmt::print("          +- {:.2g} {:.2g} {:.2g} {:.2g} {:.2g} {:.2g}\n", e.inertia_std(0), e.inertia_std(1),
             e.inertia_std(2), e.inertia_std(3), e.inertia_std(4), e.inertia_std(5));
  fmt::print("  {}\n", e.status);
  fmt::print("  estimator: {}\n",
             e.instrumented ? "instrumental variables (the reference motion's regressor)" : "least squares");
  if (!e.instrumented && std::all_of(logs.begin(), logs.end(), [](const io::Log& l) { return l.has_references(); }))
    fmt::print(
        "  the logs carry their reference motion: --instruments reference takes out least squares' bias from "
        "the encoders' noise a closed loop answers (docs/payload.md)\n");
  if (e.tare_samples > 0)
    fmt::print(
        "  tare: {} samples without the payload; the arm's own error along the payload's parameters, taken out: "
        "mass {:.3g} kg, first moments [{:.3g}, {:.3g}, {:.3g}] kg m, second moments XX..ZZ [{:.3g} {:.3g} {:.3g} "
        "{:.3g} {:.3g} {:.3g}] kg m^2 (link frame)\n",
        e.tare_samples, e.tare(9), e.tare(6), e.tare(7), e.tare(8), e.tare(0), e.tare(1), e.tare(2), e.tare(3),
        e.tare(4), e.tare(5));
  fmt::print(
      "  {} samples at {:.0f} ms, torque delay {:g} ms ({}), covariance over {} lags, scaled condition number "
      "{:.3g}\n",
      e.samples, o.interval_ms, timing.torque_delay_ms, timing.why, e.lags, e.condition);
  std::string line = "  residual RMS per joint, N m, the arm alone -> with the payload:";
  for (int j = 0; j < d.nq; ++j) line += fmt::format(" {:.4f}->{:.4f}", e.rms_without(j), e.rms_with(j));
  fmt::print("{}\n", line);

  fs::create_directories(out);
  const payload::PayloadFileContext context{
      common.robot, d.variant.empty() ? "full" : d.variant, o.params, flange, po.flange_in_link, names};
  io::write_file_atomically(yaml_file, payload::payload_yaml(e, context));
  const std::string parent = flange.rfind("frame ", 0) == 0 ? fmt::format("link{}", e.link) : flange;
  io::write_file_atomically(
      urdf_file, fmt::format("<!-- dynid payload: the payload as a URDF link on a fixed joint at the flange {}; "
                             "paste it into the robot's URDF (or dynid export --into ... --payload) -->\n{}",
                             flange, payload::payload_urdf(p, parent)));
  std::string franka = payload::franka_load(p);
  for (auto& c : franka)
    if (c == '\n') c = ';';
  fmt::print("Franka (libfranka setLoad): {}\n", franka);
  fmt::print("UR: {}\nKUKA: {}\n", payload::ur_payload(p), payload::kuka_load(p));
  fmt::print("payload: {}; URDF link: {}\n", yaml_file.string(), urdf_file.string());
}

}  // namespace

void add_payload_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<PayloadCliOptions>();
  auto* cmd = app.add_subcommand("payload",
                                 "A payload's 10 inertial parameters (mass, CoM, inertia) from logs of the arm "
                                 "carrying it, on top of the arm's identified parameters");
  add_robot_options(cmd, common);
  cmd->add_option("--params", o->params, "The arm's identified parameters (a study's report/parameters.yaml)")
      ->required();
  cmd->add_option("--model", o->model, "Model: a robot.yaml variant or full (default: the parameters file's)");
  cmd->add_option("inputs", o->inputs, "Logs (CSV with its .meta.yaml) or dataset folders of the arm carrying it")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->add_option("-o,--out", o->out, "Folder for payload.yaml and payload.urdf")->required();
  cmd->add_option("--tare", o->tare,
                  "Logs or dataset folders of the arm without the payload, best on the same motion: the arm's own "
                  "error along the payload's parameters is fitted from them and taken out (docs/payload.md); one path "
                  "each, repeatable")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::ExistingPath);
  cmd->add_option("--mass", o->mass, "The payload's known mass, kg: the other 9 parameters are identified")
      ->check(numbers::checked(0, 1e4, true, false, "above 0 and at most 1e4 kg"));
  numbers::add_log_options(cmd, o->interval_ms, o->torque_delay_ms, o->trial);
  cmd->add_option("--instruments", o->instruments,
                  "reference: instrumental variables, the regressor of the logged reference motion (q_ref, "
                  "qd_ref) instrumenting the measured one; unbiased by the encoders' noise a closed loop answers "
                  "(docs/payload.md), needs logs with reference columns (default none: least squares)")
      ->check(CLI::IsMember({"none", "reference"}));
  cmd->add_flag("--force", o->force, "Overwrite existing output files");
  cmd->callback([&common, o, cmd] {
    o->torque_delay_given = cmd->count("--torque-delay") > 0;
    run(common, *o);
  });
}

}  // namespace symoro::dynid
