#include "symoro/study/prediction.hpp"

#include "symoro/study/options.hpp"

namespace symoro::study {

Prediction predict(const io::Log& log, const identify::IdentificationModel& model, const Eigen::VectorXd& phi,
                   const PredictionOptions& options) {
  preprocess::Options po = StudyOptions{}.preprocess;
  po.torque_delay = options.torque_delay;
  Prediction p;
  p.samples = preprocess::preprocess(log, options.interval, po);
  p.tau_model = model.open_loop_torque(p.samples, phi);
  const auto n = static_cast<double>(p.samples.tau.rows());
  p.rmse = ((p.samples.tau - p.tau_model).colwise().squaredNorm() / n).cwiseSqrt().transpose();
  p.rms = (p.samples.tau.colwise().squaredNorm() / n).cwiseSqrt().transpose();
  p.raw = raw_torque_error(
      log, [&](const preprocess::Samples& m, const Eigen::VectorXd& x) { return model.open_loop_torque(m, x); }, phi);
  return p;
}

}  // namespace symoro::study
