// Band-limited resampling of a measurement set onto the model's uniform grid
// t_k = k h, k = 0..m (docs/zones_and_sensors.md, "Resampling"):
//   1. down-sampling (a longer new step) first low-passes every channel with the
//      pre-filter's zero-phase Butterworth (order 8) at 0.4 / h_new, so nothing folds back;
//   2. each new sample is the Lanczos-windowed sinc interpolation of the samples x_i at
//      t_i = t_0 + i h_old,
//        x(t) = sum_i x_i L((t - t_i) / h_old),  L(u) = sinc(u) sinc(u / a), |u| < a,
//      a = 8 lobes: exact at the data's own samples. Before t_0 the signal is zero (the
//      bar at rest); past the last sample its last value is held. A kink rings over the
//      kernel's 8 lobes.
// The data must cover the model's window: t_0 <= 0 and t_last >= m h, to 1e-6 h_old;
// with at_rest_before, t_0 > 0 is accepted too: the model's samples before it are the
// rest state the kernel already assumes there (a record that starts after the impact,
// before the waves reach its gauges).
#pragma once

#include <string>

#include "mcrewave/data/channel_set.h"

namespace mcrewave {

// The set on t_k = k step, k = 0..samples - 1, channel by channel (names and kinds
// kept). Throws InputError naming `name` when the data do not cover
// [0, (samples - 1) step] (its start may lie inside it with at_rest_before). Preconditions: step >
// 0, samples >= 2.
ChannelSet ResampleMeasurements(const ChannelSet& data, double step, int samples,
                                const std::string& name, bool at_rest_before = false);

}  // namespace mcrewave
