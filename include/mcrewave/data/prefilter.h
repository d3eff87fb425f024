// Zero-phase low-pass pre-filter of measured channels (docs/robustness.md, step 3).
//
// The same low-pass on every channel removes the white noise above the load's band
// without changing what the MCRE compares: the model is linear and time-invariant, so
// driven by the filtered forces it responds with the filtered displacements (up to edge
// effects).
//
// Filter: Butterworth of even order N as N/2 second-order sections (bilinear transform
// with pre-warping), run forward then backward (filtfilt): zero phase, magnitude
// |H(f)|^2. Edges: the record is extended over three periods of the cut-off by odd
// reflection of its residual from a cubic fitted over one period, each section started
// in its steady state for the first padded sample. A record at rest before its first
// sample (at_rest_before_start) is instead extended at its start by zeros, the filter
// starting at rest.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/data/measurement.h"

namespace mcrewave {

struct PrefilterOptions {
  // On by default (why: docs/robustness.md, "Measurements").
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

// A cut-off derived from the bar's measured load fL [Hz]: twice the upper edge of the
// load's band, clamped to [2 / T, 0.45 x sample rate]. The band is where its
// periodogram (averaged over 9 bins) stands above both 3 x the white-noise level
// (estimated from the upper half of the band) and 1e-5 x its peak, from the peak up,
// across gaps no wider than the band below them (docs/robustness.md, "Measurements").
double EstimateCutoffFrequency(const ChannelSet& measurements);
// The same from any measured load history sampled at time_step [s].
double EstimateCutoffFrequency(const Vector& load, double time_step);

// Every channel of the set filtered by the same
// ZeroPhaseLowPass (cut-off from options or estimated). Returns the set unchanged when
// !options.enabled. Writes the cut-off used to *cutoff_used when not null. Throws
// std::invalid_argument when the options are not valid or a given cut-off is not below the Nyquist
// frequency 0.5 / measurements.time_step (LoadConfig refuses both at load time).
ChannelSet PrefilterMeasurements(const ChannelSet& measurements, const PrefilterOptions& options,
                                 double* cutoff_used = nullptr);

}  // namespace mcrewave
