// DiagnosisModel (diagnosis_model.hpp) for a generated model: the design stack compiled per
// model, the backlash stage's simulation taken from robot_backlash<Full>, which is compiled once
// per robot (diagnosis_backlash-inl.hpp: its own unit), not in every model's unit. Compiled into
// symoro::<robot>_diagnosis (cmake/SymoroRobots.cmake); include it only to instantiate a model
// that has no such library.
#pragma once

#include <cstddef>
#include <memory>
#include <tuple>
#include <vector>

#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/diagnose/stack_builder.hpp"
#include "symoro/identify/identification_model.hpp"

namespace symoro::diagnose {
namespace detail {

// fit_backlash<Full> (backlash_fit.hpp), defined in diagnosis_backlash-inl.hpp.
template <class Full>
BacklashFit robot_backlash(const io::Log& measured, const trajectory::SampledReference& reference,
                           const twin::TwinConfig& nominal, const BacklashFitOptions& options);

template <class Full, class Model>
class GeneratedDiagnosisModel final : public DiagnosisModel {
 public:
  const identify::ModelDescription& description() const override {
    return identify::identification_model<Model>()->description();
  }
  DesignStack stack_design(const std::vector<NamedSamples>& runs, const StackOptions& options) const override {
    return diagnose::stack_design<Full, Model>(runs, options);
  }
  BacklashFit fit_backlash(const io::Log& measured, const trajectory::SampledReference& reference,
                           const twin::TwinConfig& nominal, const BacklashFitOptions& options) const override {
    return robot_backlash<Full>(measured, reference, nominal, options);
  }
};

}  // namespace detail

template <class Full, class Model>
std::shared_ptr<const DiagnosisModel> diagnosis_model() {
  static const std::shared_ptr<const DiagnosisModel> model = std::make_shared<detail::GeneratedDiagnosisModel<Full, Model>>();
  return model;
}

namespace detail {

// Instantiates diagnosis_model<Full, M>() for model I of a robot's Models, and with Tail for
// every later one too (cmake/diagnosis_unit.cpp.in: one unit per model of each robot).
using DiagnosisModelFactory = std::shared_ptr<const DiagnosisModel> (*)();
template <class Full, class Models, std::size_t I, bool Tail>
void instantiate_diagnosis_models(std::vector<DiagnosisModelFactory>& out) {
  if constexpr (I < std::tuple_size_v<Models>) {
    out.push_back(&diagnosis_model<Full, std::tuple_element_t<I, Models>>);
    if constexpr (Tail) instantiate_diagnosis_models<Full, Models, I + 1, true>(out);
  }
}

}  // namespace detail
}  // namespace symoro::diagnose
