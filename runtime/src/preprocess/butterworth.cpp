#include "symoro/preprocess/butterworth.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

namespace symoro::preprocess {

namespace {

constexpr double kPi = 3.14159265358979323846;

// A section whose zeros sit at z = -1 (the bilinear image of the analog zeros at infinity),
// scaled to unit DC gain.
Biquad conjugate_pair_section(std::complex<double> pole) {
  Biquad s;
  s.a1 = -2 * pole.real();
  s.a2 = std::norm(pole);
  const double gain = (1 + s.a1 + s.a2) / 4;
  s.b0 = gain;
  s.b1 = 2 * gain;
  s.b2 = gain;
  return s;
}

Biquad real_pole_section(double pole) {
  Biquad s;
  s.a1 = -pole;
  const double gain = (1 + s.a1) / 2;
  s.b0 = gain;
  s.b1 = gain;
  return s;
}

// Largest pole radius of one section (roots of z^2 + a1 z + a2).
double pole_radius(const Biquad& s) {
  const double disc = s.a1 * s.a1 - 4 * s.a2;
  if (disc < 0) return std::sqrt(s.a2);  // complex pair: |z|^2 = a2
  const double r = std::sqrt(disc);
  return std::max(std::abs((-s.a1 + r) / 2), std::abs((-s.a1 - r) / 2));
}

}  // namespace

std::vector<Biquad> butterworth_lowpass(int order, double cutoff_hz, double sample_rate_hz) {
  if (order < 1 || !(sample_rate_hz > 0) || !(cutoff_hz > 0) || !(cutoff_hz < sample_rate_hz / 2))
    throw std::invalid_argument("butterworth_lowpass: need order >= 1 and 0 < cutoff (" + std::to_string(cutoff_hz) +
                                " Hz) < sample rate / 2 (" + std::to_string(sample_rate_hz / 2) + " Hz)");
  // Prewarping: the analog cutoff whose bilinear image is exactly the digital cutoff.
  const double two_fs = 2 * sample_rate_hz;
  const double warped = two_fs * std::tan(kPi * cutoff_hz / sample_rate_hz);
  std::vector<Biquad> sections;
  // Analog poles on the left half circle of radius `warped`; one of each conjugate pair.
  for (int k = 0; k < order / 2; ++k) {
    const double angle = kPi * (2 * k + order + 1) / (2.0 * order);
    const std::complex<double> analog = warped * std::polar(1.0, angle);
    sections.push_back(conjugate_pair_section((two_fs + analog) / (two_fs - analog)));
  }
  if (order % 2 == 1) sections.push_back(real_pole_section((two_fs - warped) / (two_fs + warped)));
  std::stable_sort(sections.begin(), sections.end(),
                   [](const Biquad& a, const Biquad& b) { return pole_radius(a) < pole_radius(b); });
  return sections;
}

double slowest_time_constant(const std::vector<Biquad>& sections) {
  double radius = 0;
  for (const Biquad& s : sections) radius = std::max(radius, pole_radius(s));
  if (radius <= 0) return 0;  // FIR: no memory beyond its length
  if (radius >= 1) throw std::invalid_argument("slowest_time_constant: unstable cascade");
  return -1 / std::log(radius);
}

}  // namespace symoro::preprocess
