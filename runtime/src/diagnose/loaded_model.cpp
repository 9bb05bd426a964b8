#include "symoro/diagnose/loaded_model.hpp"

#include <stdexcept>

#include "symoro/identify/loaded_model.hpp"

namespace symoro::diagnose {
namespace {

using robot::ModelHandle;

StackModel stack_model(const ModelHandle& m, const ModelHandle& full) {
  if (full.nq() != m.nq()) throw std::invalid_argument("the full and diagnosed models must have the same joints");
  StackModel s;
  s.nq = m.nq();
  s.np = m.np();
  s.ns = m.ns();
  s.joints = m.joints();
  s.parameters = m.parameters();
  s.full_parameters = full.parameters();
  s.standard = m.standard_parameters();
  s.regressor = [m](const double* q, const double* qd, const double* qdd, double* w) { m.regressor(q, qd, qdd, w); };
  s.fixed_torque = [m](const double* q, const double* qd, const double* qdd, double* t) {
    m.fixed_torque(q, qd, qdd, t);
  };
  s.full_regressor = [full](const double* q, const double* qd, const double* qdd, double* w) {
    full.regressor(q, qd, qdd, w);
  };
  s.base_from_standard = [m](const double* st, double* phi) { m.base_from_standard(st, phi); };
  return s;
}

class LoadedDiagnosisModel final : public DiagnosisModel {
 public:
  LoadedDiagnosisModel(const ModelHandle& model, const ModelHandle& full)
      : identification_(identify::identification_model(model, full)), stack_(stack_model(model, full)), full_(full) {}
  const identify::ModelDescription& description() const override { return identification_->description(); }
  DesignStack stack_design(const std::vector<NamedSamples>& runs, const StackOptions& options) const override {
    return diagnose::stack_design(stack_, runs, options);
  }
  BacklashFit fit_backlash(const io::Log& measured, const trajectory::SampledReference& reference,
                           const twin::TwinConfig& nominal, const BacklashFitOptions& options) const override {
    return diagnose::fit_backlash(full_, measured, reference, nominal, options);
  }

 private:
  std::shared_ptr<const identify::IdentificationModel> identification_;
  StackModel stack_;
  ModelHandle full_;  // the twin's plant
};

}  // namespace

std::shared_ptr<const DiagnosisModel> diagnosis_model(const robot::ModelHandle& model, const robot::ModelHandle& full) {
  return std::make_shared<LoadedDiagnosisModel>(model, full);
}

}  // namespace symoro::diagnose
