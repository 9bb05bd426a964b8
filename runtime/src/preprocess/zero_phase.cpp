#include "symoro/preprocess/zero_phase.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace symoro::preprocess {

namespace {

// A cascade in direct form II transposed running over rows of channels, its state carried
// from one stretch of rows to the next (padding, data, padding).
class Cascade {
 public:
  Cascade(const std::vector<Biquad>& sections, Eigen::Index channels)
      : sections_(sections),
        z1_(channels, static_cast<Eigen::Index>(sections.size())),
        z2_(channels, static_cast<Eigen::Index>(sections.size())) {}

  // At rest on a constant input `row` (scipy's sosfilt_zi * x[0]): y = gain u in the update
  // equations, each section's steady input being the previous one's steady output.
  void start_at_rest(const double* row) {
    Eigen::ArrayXd u = Eigen::Map<const Eigen::ArrayXd>(row, z1_.rows());
    for (Eigen::Index i = 0; i < z1_.cols(); ++i) {
      const Biquad& s = sections_[i];
      const double gain = s.dc_gain();
      z1_.col(i) = ((s.b1 + s.b2) - (s.a1 + s.a2) * gain) * u;
      z2_.col(i) = (s.b2 - s.a2 * gain) * u;
      u *= gain;
    }
  }

  // Filters `count` rows in place, starting at `row` and moving by `step` rows (+1 or -1).
  void run(double* row, Eigen::Index count, Eigen::Index step) {
    const Eigen::Index channels = z1_.rows();
    for (Eigen::Index k = 0; k < count; ++k, row += step * channels) {
      for (Eigen::Index i = 0; i < z1_.cols(); ++i) {
        const Biquad s = sections_[i];
        // Distinct arrays (the compiler cannot know it): a plain loop it vectorizes.
        double* __restrict x = row;
        double* __restrict z1 = z1_.col(i).data();
        double* __restrict z2 = z2_.col(i).data();
        for (Eigen::Index c = 0; c < channels; ++c) {
          const double u = x[c];
          const double y = s.b0 * u + z1[c];
          z1[c] = s.b1 * u - s.a1 * y + z2[c];
          z2[c] = s.b2 * u - s.a2 * y;
          x[c] = y;
        }
      }
    }
  }

 private:
  const std::vector<Biquad>& sections_;
  Eigen::ArrayXXd z1_, z2_;  // channels x sections
};

}  // namespace

int zero_phase_padding(const std::vector<Biquad>& sections) {
  return static_cast<int>(std::ceil(3 * slowest_time_constant(sections)));
}

void filtfilt(const std::vector<Biquad>& sections, int padding, Channels& signals) {
  const Eigen::Index n = signals.rows(), channels = signals.cols();
  if (padding < 0 || padding >= n)
    throw std::invalid_argument("filtfilt: padding " + std::to_string(padding) +
                                " needs more than that many samples, got " + std::to_string(n));
  // Odd reflections about each end sample, in time order: value and slope continue across.
  Channels before(padding, channels), after(padding, channels);
  for (Eigen::Index i = 0; i < padding; ++i) {
    before.row(i) = 2 * signals.row(0) - signals.row(padding - i);
    after.row(i) = 2 * signals.row(n - 1) - signals.row(n - 2 - i);
  }
  Cascade cascade(sections, channels);
  // Forward over before | signals | after; the outputs over `before` are not needed.
  cascade.start_at_rest(padding > 0 ? before.data() : signals.data());
  cascade.run(before.data(), padding, 1);
  cascade.run(signals.data(), n, 1);
  cascade.run(after.data(), padding, 1);
  // Backward from the end of the forward output, through `after` back to the first sample.
  double* last =
      padding > 0 ? after.data() + (padding - 1) * channels : signals.data() + (n - 1) * channels;
  cascade.start_at_rest(last);
  cascade.run(last, padding, -1);
  cascade.run(signals.data() + (n - 1) * channels, n, -1);
}

}  // namespace symoro::preprocess
