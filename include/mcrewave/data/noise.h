// Measurement noise.
//
// SNR definition (the paper gives none): per quantity type, SNR = RMS(signal) /
// std(noise), the same noise standard deviation applied to every channel of that type:
//   displacements (u0, uL and every u@X):  std_u = RMS(uL) / snr,
//   strains (every e@X):                   std_e = RMS over all strain channels / snr,
//   forces (f0, fL):                       std_f = RMS(fL) / snr.
// The noise is Gaussian and white, drawn in the order u0, uL, f0, fL, then the
// interior sensors in their order (all samples of one channel, then the next) from a
// 64-bit Mersenne twister seeded with `seed` and a Box-Muller transform written here,
// so the same seed gives the same numbers on every platform and the end channels the
// same draws with or without sensors; the same seed at two SNRs gives the same
// standard-normal draw, scaled by each std.
#pragma once

#include <cstdint>

#include "mcrewave/data/measurement.h"

namespace mcrewave {

// Adds noise in place. snr = +inf adds nothing. Precondition: snr > 0.
void AddMeasurementNoise(double snr, std::uint64_t seed, MeasurementSet* measurements);

// Root mean square of a channel.
double RootMeanSquare(const Vector& channel);

}  // namespace mcrewave
