#include "mcrewave/data/resample.h"

#include <cassert>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "mcrewave/core/format.h"
#include "mcrewave/data/prefilter.h"

namespace mcrewave {
namespace {

constexpr int kLobes = 8;  // a of the Lanczos window

// L(u) = sinc(u) sinc(u / a) for |u| < a, 0 beyond; sinc(u) = sin(pi u) / (pi u).
double Lanczos(double u) {
  if (u == 0.0) return 1.0;
  // Zero at the other integers exactly (sin(k pi) is not 0 in floating point).
  if (std::abs(u) >= kLobes || u == std::round(u)) return 0.0;
  const double pu = M_PI * u;
  return kLobes * std::sin(pu) * std::sin(pu / kLobes) / (pu * pu);
}

// The channel at t_k = k step, from x_i at t_0 + i h (rest before t_0, held after).
Vector Interpolate(const Vector& values, double start, double h, double step, int samples) {
  Vector out(samples);
  const Eigen::Index count = values.size();
  for (int k = 0; k < samples; ++k) {
    double position = (k * step - start) / h;  // in units of the old step
    // On the data's own samples (to round-off) exactly there.
    if (std::abs(position - std::round(position)) < 1e-9) position = std::round(position);
    const auto center = static_cast<Eigen::Index>(std::floor(position));
    double sum = 0.0;
    for (Eigen::Index i = center - kLobes + 1; i <= center + kLobes; ++i) {
      const double sample = i < 0 ? 0.0 : values[std::min(i, count - 1)];
      sum += sample * Lanczos(position - static_cast<double>(i));
    }
    out[k] = sum;
  }
  return out;
}

std::string Short(double value) { return FormatNumber(value, kSixDigits); }

}  // namespace

ChannelSet ResampleMeasurements(const ChannelSet& data, double step, int samples,
                                const std::string& name, bool at_rest_before) {
  assert(step > 0.0 && samples >= 2);
  const double h = data.time_step;
  const double tolerance = 1e-6 * h;
  const double end = data.Time(data.num_samples() - 1);
  const double window = (samples - 1) * step;
  if ((data.start_time > tolerance && !at_rest_before) || end < window - tolerance) {
    throw InputError(name + ": the data span [" + Short(data.start_time) + ", " + Short(end) +
                     "] s does not cover the model's window [0, " + Short(window) +
                     "] s (time.window" +
                     (at_rest_before ? std::string(")")
                                     : "; data.at_rest_before_record takes every channel as 0 "
                                       "before the record's first sample)"));
  }
  ChannelSet out;
  out.start_time = 0.0;
  out.time_step = step;
  out.channels.reserve(data.channels.size());
  if (step > h) {
    // Down-sampling: low-pass below the new Nyquist frequency first (order 8, from
    // rest: the record is at rest before its first sample).
    const ZeroPhaseLowPass filter(0.4 / step, 1.0 / h, 8);
    for (const Channel& channel : data.channels) {
      out.channels.push_back(
          {channel.name, channel.kind,
           Interpolate(filter.Apply(channel.values, /*at_rest_before_start=*/true), data.start_time,
                       h, step, samples)});
    }
  } else {
    for (const Channel& channel : data.channels) {
      out.channels.push_back({channel.name, channel.kind,
                              Interpolate(channel.values, data.start_time, h, step, samples)});
    }
  }
  return out;
}

}  // namespace mcrewave
