#include "symoro/identify/prediction.hpp"

#include "symoro/identify/study_options.hpp"

namespace symoro::identify {

Prediction predict(const io::Log& log, const IdentificationModel& model, const Eigen::VectorXd& phi, double interval,
                   double torque_delay) {
  preprocess::Options po = StudyOptions{}.preprocess;
  po.torque_delay = torque_delay;
  Prediction p;
  p.samples = preprocess::preprocess(log, interval, po);
  p.tau_model = model.open_loop_torque(p.samples, phi);
  const auto n = static_cast<double>(p.samples.tau.rows());
  p.rmse = ((p.samples.tau - p.tau_model).colwise().squaredNorm() / n).cwiseSqrt().transpose();
  p.rms = (p.samples.tau.colwise().squaredNorm() / n).cwiseSqrt().transpose();
  p.raw = raw_torque_error(
      log, [&](const preprocess::Samples& m, const Eigen::VectorXd& x) { return model.open_loop_torque(m, x); }, phi);
  return p;
}

}  // namespace symoro::identify
