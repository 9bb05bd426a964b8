#include "symoro/preprocess/zero_phase.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace symoro::preprocess {

// Named, not anonymous: SampledZeroPhase::State (a class with linkage) holds one.
namespace zero_phase_detail {

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

  // The state of channel 0 as one vector (z1, z2 of each section in turn), and back.
  Eigen::VectorXd state() const {
    Eigen::VectorXd z(2 * z1_.cols());
    for (Eigen::Index i = 0; i < z1_.cols(); ++i) {
      z(2 * i) = z1_(0, i);
      z(2 * i + 1) = z2_(0, i);
    }
    return z;
  }
  void set_state(const Eigen::VectorXd& z) {
    for (Eigen::Index i = 0; i < z1_.cols(); ++i) {
      z1_(0, i) = z(2 * i);
      z2_(0, i) = z(2 * i + 1);
    }
  }

 private:
  const std::vector<Biquad>& sections_;
  Eigen::ArrayXXd z1_, z2_;  // channels x sections
};

}  // namespace zero_phase_detail

using zero_phase_detail::Cascade;

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
  double* last = padding > 0 ? after.data() + (padding - 1) * channels : signals.data() + (n - 1) * channels;
  cascade.start_at_rest(last);
  cascade.run(last, padding, -1);
  cascade.run(signals.data() + (n - 1) * channels, n, -1);
}

struct SampledZeroPhase::State {
  State(const std::vector<Biquad>& s, int p, Eigen::Index n, Eigen::Index c)
      : sections(s), padding(p), rows(n), channels(c), forward(sections, c) {}
  std::vector<Biquad> sections;
  int padding;
  Eigen::Index rows, channels, pushed = 0;
  Cascade forward;
  Channels head, ring;                       // the first padding + 1 rows; the last padding + 1 rows (raw)
  Eigen::ArrayXd tmp;                        // one row through the forward pass
  std::vector<Eigen::Index> wanted, unique;  // as asked; sorted without repeats
  // The backward cascade as z <- A z + B u, y = c z + d u; at rest on u: z = rest u.
  Eigen::MatrixXd A;
  Eigen::VectorXd B, c, rest;
  double d = 0;
  std::vector<Eigen::VectorXd> power;  // power[p] = A^p B
  // Block i: sum over forward outputs u_e, unique[i] < e <= unique[i + 1] (the last block: to the
  // end of the padding) of A^(e - unique[i] - 1) B u_e (dim rows of channels each); and the forward
  // output at unique[i] itself.
  Channels blocks, at_row;
  Eigen::ArrayXd last;  // the forward output at the very end
  Eigen::Index block = -1;

  // Forward output u at index e of the padded signal (e = row, or rows + i in the end padding).
  void consume(const double* u, Eigen::Index e) {
    const Eigen::Index m = static_cast<Eigen::Index>(unique.size()), dim = B.size();
    while (block + 1 < m && unique[static_cast<std::size_t>(block + 1)] < e) ++block;
    if (block >= 0) {
      const Eigen::VectorXd& g = power[static_cast<std::size_t>(e - unique[static_cast<std::size_t>(block)] - 1)];
      for (Eigen::Index k = 0; k < dim; ++k) {
        double* __restrict acc = blocks.row(block * dim + k).data();
        const double w = g(k);
        for (Eigen::Index ch = 0; ch < channels; ++ch) acc[ch] += w * u[ch];
      }
    }
    if (block + 1 < m && unique[static_cast<std::size_t>(block + 1)] == e)
      at_row.row(block + 1) = Eigen::Map<const Eigen::RowVectorXd>(u, channels);
    if (e == rows + padding - 1) last = Eigen::Map<const Eigen::ArrayXd>(u, channels);
  }
  void step(const double* x, Eigen::Index e) {
    tmp = Eigen::Map<const Eigen::ArrayXd>(x, channels);
    forward.run(tmp.data(), 1, 1);
    consume(tmp.data(), e);
  }
};

SampledZeroPhase::SampledZeroPhase(const std::vector<Biquad>& sections, int padding, Eigen::Index rows,
                                   Eigen::Index channels, const std::vector<Eigen::Index>& wanted)
    : s_(std::make_unique<State>(sections, padding, rows, channels)) {
  if (padding < 0 || padding >= rows)
    throw std::invalid_argument("SampledZeroPhase: padding " + std::to_string(padding) +
                                " needs more than that many samples, got " + std::to_string(rows));
  State& s = *s_;
  s.wanted = wanted;
  s.unique = wanted;
  std::sort(s.unique.begin(), s.unique.end());
  s.unique.erase(std::unique(s.unique.begin(), s.unique.end()), s.unique.end());
  if (!s.unique.empty() && (s.unique.front() < 0 || s.unique.back() >= rows))
    throw std::invalid_argument("SampledZeroPhase: a wanted row lies outside the signal");
  s.head.resize(padding + 1, channels);
  s.ring.resize(padding + 1, channels);
  // The backward cascade's matrices, by running one channel on unit states and inputs.
  Cascade one(s.sections, 1);
  const Eigen::Index dim = 2 * static_cast<Eigen::Index>(sections.size());
  s.A.resize(dim, dim);
  s.c.resize(dim);
  for (Eigen::Index j = 0; j < dim; ++j) {
    one.set_state(Eigen::VectorXd::Unit(dim, j));
    double u = 0;
    one.run(&u, 1, 1);
    s.c(j) = u;
    s.A.col(j) = one.state();
  }
  one.set_state(Eigen::VectorXd::Zero(dim));
  double u = 1;
  one.run(&u, 1, 1);
  s.d = u;
  s.B = one.state();
  u = 1;
  one.start_at_rest(&u);
  s.rest = one.state();
  Eigen::Index longest = 1;
  for (std::size_t i = 0; i + 1 < s.unique.size(); ++i) longest = std::max(longest, s.unique[i + 1] - s.unique[i]);
  if (!s.unique.empty()) longest = std::max(longest, rows + padding - 1 - s.unique.back());
  s.power.resize(static_cast<std::size_t>(longest) + 1);
  s.power[0] = s.B;
  for (std::size_t p = 1; p < s.power.size(); ++p) s.power[p] = s.A * s.power[p - 1];
  const Eigen::Index m = static_cast<Eigen::Index>(s.unique.size());
  s.blocks = Channels::Zero(m * dim, channels);
  s.at_row.resize(m, channels);
}

SampledZeroPhase::~SampledZeroPhase() = default;

void SampledZeroPhase::push(const double* row) {
  State& s = *s_;
  const Eigen::Index k = s.pushed++, P = s.padding, C = s.channels;
  if (k >= s.rows) throw std::logic_error("SampledZeroPhase: more rows than announced");
  const auto x = Eigen::Map<const Eigen::RowVectorXd>(row, C);
  s.ring.row(k % (P + 1)) = x;
  if (k <= P) s.head.row(k) = x;
  if (k == P) {
    // The start padding (filtfilt's `before`), then the rows held so far.
    Channels before(P, C);
    for (Eigen::Index i = 0; i < P; ++i) before.row(i) = 2 * s.head.row(0) - s.head.row(P - i);
    s.forward.start_at_rest(P > 0 ? before.data() : s.head.data());
    s.forward.run(before.data(), P, 1);
    for (Eigen::Index i = 0; i <= P; ++i) s.step(s.head.row(i).data(), i);
  } else if (k > P) {
    s.step(row, k);
  }
  if (k == s.rows - 1) {
    // The end padding: after(i) = 2 x(n - 1) - x(n - 2 - i), from the ring.
    Eigen::RowVectorXd a(C);
    for (Eigen::Index i = 0; i < P; ++i) {
      a = 2 * s.ring.row((s.rows - 1) % (P + 1)) - s.ring.row((s.rows - 2 - i) % (P + 1));
      s.step(a.data(), s.rows + i);
    }
  }
}

void SampledZeroPhase::finish(Channels& out) {
  State& s = *s_;
  if (s.pushed != s.rows) throw std::logic_error("SampledZeroPhase: finished before the last row");
  const Eigen::Index m = static_cast<Eigen::Index>(s.unique.size()), dim = s.B.size(), C = s.channels;
  Channels y(m, C);
  if (m > 0) {
    // Backward from the end: at rest on the last output, A^(steps to the last wanted row) of it.
    const Eigen::Index end = s.rows + s.padding - 1;
    Eigen::VectorXd start = s.rest;
    for (Eigen::Index p = 0; p < end - s.unique.back(); ++p) start = s.A * start;
    Eigen::MatrixXd z = s.blocks.middleRows((m - 1) * dim, dim) + start * s.last.matrix().transpose();
    for (Eigen::Index i = m - 1;; --i) {
      y.row(i) = s.c.transpose() * z + s.d * s.at_row.row(i);
      if (i == 0) break;
      Eigen::MatrixXd a = Eigen::MatrixXd::Identity(dim, dim);
      for (Eigen::Index p = 0; p < s.unique[static_cast<std::size_t>(i)] - s.unique[static_cast<std::size_t>(i - 1)];
           ++p)
        a = s.A * a;
      z = a * z + s.blocks.middleRows((i - 1) * dim, dim);
    }
  }
  out.resize(static_cast<Eigen::Index>(s.wanted.size()), C);
  for (std::size_t w = 0; w < s.wanted.size(); ++w) {
    const auto i = std::lower_bound(s.unique.begin(), s.unique.end(), s.wanted[w]) - s.unique.begin();
    out.row(static_cast<Eigen::Index>(w)) = y.row(i);
  }
}

}  // namespace symoro::preprocess
