// What the diagnosis needs of a robot model, behind one small virtual interface, so that the
// whole diagnosis of a dataset (diagnose_dataset.hpp: the stepwise selection, the raw-torque
// gap, the backlash stage, the report and the variant) is compiled once for every robot: one
// implementation over robot::ModelHandle (loaded_model.hpp), for a loaded robot library and a
// linked model alike. dynid diagnose and the Python package both call it.
#pragma once

#include <memory>
#include <vector>

#include "symoro/diagnose/backlash_fit.hpp"
#include "symoro/diagnose/design_stack.hpp"
#include "symoro/diagnose/stack_builder.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/io/log.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::diagnose {

class DiagnosisModel {
 public:
  virtual ~DiagnosisModel() = default;
  // The diagnosed model's description (its identification interface's).
  virtual const identify::ModelDescription& description() const = 0;
  // stack_design<Full, Model>: the regression of the diagnosed model, the full model's extra
  // columns and the candidate effects, over runs preprocessed at their own rate.
  virtual DesignStack stack_design(const std::vector<NamedSamples>& runs, const StackOptions& options) const = 0;
  // fit_backlash: the closed-loop high-band stage on the robot's twin (its full model's plant).
  virtual BacklashFit fit_backlash(const io::Log& measured, const trajectory::SampledReference& reference,
                                   const twin::TwinConfig& nominal, const BacklashFitOptions& options) const = 0;
};

// The interface of model Model of the robot whose full model is Full, one shared instance per
// model. Defined in diagnosis_model-inl.hpp and compiled for every model of a robot into
// symoro::<robot>_diagnosis: link it (or include the -inl header to compile it here).
template <class Full, class Model>
std::shared_ptr<const DiagnosisModel> diagnosis_model();

}  // namespace symoro::diagnose
