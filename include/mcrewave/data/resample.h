// Band-limited resampling of a measurement set onto another uniform time grid.
//
// Measured data sampled at another rate than the model's step are brought onto the
// model's grid t_k = k h, k = 0..m (docs/zones_and_sensors.md, "Resampling"):
//
//   1. When the new step is longer (down-sampling), every channel first goes through
//      the zero-phase Butterworth low-pass of the pre-filter (order 8) at 0.4 / h_new,
//      below the new Nyquist frequency 0.5 / h_new, so that nothing folds back.
//   2. Each new sample is the Lanczos-windowed sinc interpolation of the (filtered)
//      samples x_i at t_i = t_0 + i h_old,
//        x(t) = sum_i x_i L((t - t_i) / h_old),  L(u) = sinc(u) sinc(u / a), |u| < a,
//      with a = 8 lobes: band-limited to the data's Nyquist frequency, exact at the
//      data's own samples; measured errors 7e-4 of the amplitude for content at 1/20
//      of the sample rate (tests/resample_test.cpp). Before t_0 the bar is at rest
//      (zero); past the last sample its value is held. A signal that starts with a
//      kink rings over the kernel's 8 lobes.
//
// The data must cover the model's window: t_0 <= 0 and t_last >= m h, to 1e-6 h_old.
#pragma once

#include <string>

#include "mcrewave/data/measurement.h"

namespace mcrewave {

// The set on t_k = k step, k = 0..samples - 1. Throws InputError naming `name` when
// the data do not cover [0, (samples - 1) step]. Preconditions: step > 0, samples >= 2.
MeasurementSet ResampleMeasurements(const MeasurementSet& data, double step, int samples,
                                    const std::string& name);

// The same for a table of any channels (a structure given by matrices).
ChannelTable ResampleChannelTable(const ChannelTable& data, double step, int samples,
                                  const std::string& name);

}  // namespace mcrewave
