// The project's seeded standard normal generator: a 64-bit Mersenne twister and a
// Box-Muller transform written here, so that a seed gives the same numbers on every
// platform and standard library (std::normal_distribution's algorithm is the library's
// own).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace mcrewave {

class StandardNormal {
 public:
  explicit StandardNormal(std::uint64_t seed) : engine_(seed) {}
  // The next N(0, 1) draw; the two draws of one transform are returned in turn.
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    // u1 in (0, 1], u2 in [0, 1): 53-bit uniforms from the raw engine output.
    const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace mcrewave
