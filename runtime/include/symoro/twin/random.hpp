// Reproducible randomness for the twin: the same seed gives the same log on every platform
// (std::normal_distribution is implementation-defined, so the twin has its own).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

namespace symoro::twin {

// splitmix64: a well-mixed 64-bit sequence from any seed.
class Random {
 public:
  explicit Random(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return (next() >> 11) * 0x1.0p-53; }  // [0, 1)
  // Standard normal by Box-Muller; each pair of uniforms gives two values.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0) u1 = uniform();
    const double r = std::sqrt(-2 * std::log(u1)), a = 6.283185307179586 * uniform();
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  std::uint64_t s_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// The seed of one run, from the dataset seed, the trajectory and the trial: independent of
// the order in which runs execute.
inline std::uint64_t run_seed(std::uint64_t seed, const std::string& trajectory, int trial) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (unsigned char c : trajectory) h = (h ^ c) * 1099511628211ull;
  Random r(seed ^ (h + 0x632BE59BD9B4E019ull * static_cast<std::uint64_t>(trial)));
  return r.next();
}

}  // namespace symoro::twin
