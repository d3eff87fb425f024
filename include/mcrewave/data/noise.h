// Measurement noise (docs/zones_and_sensors.md, "Noise"). SNR = RMS(signal) / std(noise)
// per quantity, one std per quantity: displacements (u0, uL, every u@X) RMS(uL) / snr,
// strains RMS over all strain channels / snr, forces (f0, fL) RMS(fL) / snr. White
// Gaussian draws in the order u0, uL, f0, fL, then the interior sensors (a channel's
// samples, then the next), from a 64-bit Mersenne twister seeded with `seed` and a
// Box-Muller transform written here: the same numbers on every platform, the end
// channels' draws unchanged by added sensors, and the same standard-normal draw at
// every SNR for one seed.
#pragma once

#include <cstdint>

#include "mcrewave/data/measurement.h"

namespace mcrewave {

// Adds noise in place. snr = +inf adds nothing. Precondition: snr > 0.
void AddMeasurementNoise(double snr, std::uint64_t seed, ChannelSet* measurements);

// Root mean square of a channel.
double RootMeanSquare(const Vector& channel);

}  // namespace mcrewave
