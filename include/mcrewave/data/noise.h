// Measurement noise.
//
// SNR definition (the paper gives none; formulation.md section 1): per quantity
// type, SNR = RMS(signal) / std(noise). The RMS is taken on uL for displacements
// and on fL for forces; the same noise standard deviation is applied to both ends
// of that type:
//   std_u = RMS(uL) / snr  on u0 and uL,     std_f = RMS(fL) / snr  on f0 and fL.
// The noise is Gaussian and white, drawn in the order u0, uL, f0, fL (all samples
// of one channel, then the next) from a 64-bit Mersenne twister seeded with `seed`
// and a Box-Muller transform written here, so the same seed gives the same numbers
// on every platform; the same seed at two SNRs gives the same standard-normal draw,
// scaled by each std.
#pragma once

#include <cstdint>

#include "mcrewave/data/measurement.h"

namespace mcrewave {

// Adds noise in place. snr = +inf adds nothing. Precondition: snr > 0.
void AddMeasurementNoise(double snr, std::uint64_t seed, MeasurementSet* measurements);

// Root mean square of a channel.
double RootMeanSquare(const Vector& channel);

}  // namespace mcrewave
