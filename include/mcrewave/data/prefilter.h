// Zero-phase low-pass pre-filter of measured channels.
//
// The shock load's spectrum lies far below the sampling rate (a 0.1 ms half sine
// has its main lobe below 15 kHz; the paper's sampling rate is 2.8 MHz), so most of
// the power of white measurement noise lies where the signal has none. A low-pass
// filter applied identically to every channel removes it without changing what the
// MCRE compares: the bar is linear and time-invariant, so the model driven by the
// filtered forces responds with the filtered displacements (up to edge effects).
//
// Filter: Butterworth of even order N as N/2 second-order sections (bilinear
// transform with pre-warping), run forward then backward (filtfilt): zero phase,
// magnitude |H(f)|^2. Edges: the record is extended at both ends over three periods
// of the cut-off by odd reflection of its residual from a cubic fitted over one
// period (plain odd reflection, as scipy's filtfilt, flips the curvature at the
// junction and leaves a transient of 4e-3 of an 8 kHz sine at a 100 kHz cut-off;
// with the cubic, 7e-4), and each section starts in its steady state for the first
// padded sample. A record of a structure at rest before its first sample (the
// shock load's experiment: every channel is 0 for t < t_0) is instead extended at
// its start by those zeros, the filter starting at rest: the first samples' noise
// is then averaged like any other sample's, where the reflection keeps it (it pins
// the extension to x_0).
#pragma once

#include <string>
#include <vector>

#include "mcrewave/data/measurement.h"

namespace mcrewave {

struct PrefilterOptions {
  // On by default: at SNR 2.5 on the paper's case it takes the share of noise
  // seeds identifying E within +-2 % from 78 % to 96 %, with no noise-free bias
  // (docs/robustness.md).
  bool enabled = true;
  // Cut-off frequency [Hz]; 0 derives it from the data (EstimateCutoffFrequency).
  double cutoff_frequency = 0.0;
  int order = 4;  // Butterworth order of one pass, even, 2..12
  // Every channel is 0 before the first sample (the bar at rest until the load
  // starts): the filter's start uses it (ZeroPhaseLowPass::Apply).
  bool at_rest_before_start = true;

  bool IsValid(std::string* error) const;
};

class ZeroPhaseLowPass {
 public:
  // Throws std::invalid_argument unless 0 < cutoff_frequency < sample_rate / 2 (the
  // Nyquist frequency) and order is even in [2, 12].
  ZeroPhaseLowPass(double cutoff_frequency, double sample_rate, int order);
  // The filtered signal, same length. Signals shorter than 2 samples are returned as
  // is. at_rest_before_start: the signal is 0 before its first sample (the start is
  // extended by zeros, not by reflection).
  Vector Apply(const Vector& signal, bool at_rest_before_start = false) const;
  // Magnitude of the zero-phase response |H(f)|^2 at frequency f [Hz].
  double Gain(double frequency) const;

 private:
  struct Section {
    double b0, b1, b2, a1, a2;  // y = b0 x + b1 x' + b2 x'' - a1 y' - a2 y''
  };
  void FilterInPlace(std::vector<double>* values) const;

  double cutoff_frequency_;
  double sample_rate_;
  std::vector<Section> sections_;
  int pad_;  // samples of odd reflection at each end
};

// A cut-off derived from the measured load fL [Hz]: twice the highest frequency at
// which its periodogram (averaged over 9 bins) stands above both 3 x the white-noise
// level (estimated from the upper half of the band) and 1e-5 x its peak, clamped to
// [2 / T, 0.45 x sample rate].
double EstimateCutoffFrequency(const MeasurementSet& measurements);
// The same from any measured load history sampled at time_step [s].
double EstimateCutoffFrequency(const Vector& load, double time_step);

// Every channel (the four end channels and the interior sensors) filtered by the same
// ZeroPhaseLowPass (cut-off from options or estimated). Returns the set unchanged when
// !options.enabled. Writes the cut-off used to *cutoff_used when not null. Throws
// std::invalid_argument when the options are not valid or a given cut-off is not below the Nyquist
// frequency 0.5 / measurements.time_step (LoadConfig refuses both at load time).
MeasurementSet PrefilterMeasurements(const MeasurementSet& measurements,
                                     const PrefilterOptions& options,
                                     double* cutoff_used = nullptr);

}  // namespace mcrewave
