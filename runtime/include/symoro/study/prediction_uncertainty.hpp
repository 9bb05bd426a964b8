// The identified parameters' uncertainty as plain data (prediction_band.hpp computes and uses it;
// the study keeps it in its result and writes it as report/uncertainty.yaml).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace symoro::study {

struct PredictionUncertainty {
  std::string model;               // the model's variant ("" full)
  std::vector<std::string> names;  // phi's entries
  Eigen::MatrixXd covariance;      // np x np, of phi
  Eigen::VectorXd residual;        // per joint, N m: the residual's RMS
  std::string source;              // the samples it comes from (e.g. "AG02 at 10 ms, 2400 samples")
  int samples = 0, lags = 0;
};

}  // namespace symoro::study
