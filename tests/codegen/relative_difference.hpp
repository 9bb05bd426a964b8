// Largest |a_i - b_i| over the largest |a_i|: how far two evaluations of a model's outputs are
// apart (test_modeling.cpp, test_model_urdf.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace symoro::codegen::test {

inline double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, std::abs(a[i] - b[i]));
    scale = std::max(scale, std::abs(a[i]));
  }
  return diff / std::max(scale, 1e-300);
}

}  // namespace symoro::codegen::test
