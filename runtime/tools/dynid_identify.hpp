// dynid identify's options and its entry: a thin part per model of each robot (any variant:
// --model) in generated units (dynid_identify-inl.hpp), the body once (dynid_identify.cpp).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid_dispatch.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/study_request.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::dynid {

// The study's options are the library's request (symoro.identify takes the same), and the
// command's own.
struct IdentifyOptions : identify::StudyRequest {
  std::string model;
  bool no_report = false;
  // When set, the command hands its model here and runs nothing: the identify units double as
  // the registry of every robot's identification models (identification_model_of).
  std::function<void(std::shared_ptr<const identify::IdentificationModel>)> take_model;
};

// The twin's true parameters of the model being identified (twin data only).
using TwinTruth = std::function<Eigen::VectorXd(const twin::TwinConfig&)>;

struct IdentifyCommand {
  using Options = IdentifyOptions;
  // Per model (dynid_identify-inl.hpp): hands the model to run_model.
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
  // The study and its report, compiled once for every model (dynid_identify.cpp).
  static void run_model(const Common& common, const Options& o, std::shared_ptr<const identify::IdentificationModel> model,
                        const TwinTruth& truth);
};

const CommandTable<IdentifyOptions>& identify_units();  // generated: dynid_tables.cpp

// The identification model of common.robot named `model` (a robot.yaml variant or "full"; ""
// robot.yaml's `identified`), compiled once in symoro::<robot>_identification.
std::shared_ptr<const identify::IdentificationModel> identification_model_of(const Common& common, const std::string& model);

}  // namespace symoro::dynid
