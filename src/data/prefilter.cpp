#include "mcrewave/data/prefilter.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <stdexcept>
#include <unsupported/Eigen/FFT>

namespace mcrewave {
namespace {

// Cut-off estimation (EstimateCutoffFrequency).
constexpr double kNoiseFactor = 3.0;     // the signal stands this far above the noise mean
constexpr double kDynamicRange = 1e-5;   // or 50 dB below the peak, whichever is higher
constexpr int kSmoothingBins = 9;        // periodogram averaged over this many bins
constexpr double kCutoffOverEdge = 2.0;  // cut-off = this x the signal's band edge

}  // namespace

bool PrefilterOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(std::isfinite(cutoff_frequency) && cutoff_frequency >= 0.0)) {
    why << "prefilter.cutoff_frequency must be 0 (derived from the data) or a positive "
           "frequency in Hz, got "
        << cutoff_frequency;
  } else if (order < 2 || order > 12 || order % 2 != 0) {
    why << "prefilter.order must be an even integer in [2, 12], got " << order;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

ZeroPhaseLowPass::ZeroPhaseLowPass(double cutoff_frequency, double sample_rate, int order)
    : cutoff_frequency_(cutoff_frequency), sample_rate_(sample_rate) {
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0 && cutoff_frequency > 0.0 &&
        cutoff_frequency < 0.5 * sample_rate)) {
    std::ostringstream why;
    why << "ZeroPhaseLowPass: the cut-off frequency (" << cutoff_frequency
        << " Hz) must be positive and below the Nyquist frequency (" << 0.5 * sample_rate
        << " Hz, half the sample rate)";
    throw std::invalid_argument(why.str());
  }
  if (order < 2 || order > 12 || order % 2 != 0) {
    throw std::invalid_argument(
        "ZeroPhaseLowPass: the order must be an even integer in [2, 12], got " +
        std::to_string(order));
  }
  // Pre-warped analogue cut-off: K = tan(pi fc / fs).
  const double k = std::tan(M_PI * cutoff_frequency / sample_rate);
  for (int s = 1; s <= order / 2; ++s) {
    // Pole pair s of the Butterworth polynomial: Q_s = 1 / (2 sin((2s - 1) pi / (2N))).
    const double q = 1.0 / (2.0 * std::sin((2 * s - 1) * M_PI / (2.0 * order)));
    // Bilinear transform of w^2 / (s^2 + (w / Q) s + w^2):
    //   b = K^2 [1 2 1] / n,  a = [2 (K^2 - 1), 1 - K / Q + K^2] / n,  n = 1 + K / Q + K^2.
    const double norm = 1.0 / (1.0 + k / q + k * k);
    Section section;
    section.b0 = k * k * norm;
    section.b1 = 2.0 * section.b0;
    section.b2 = section.b0;
    section.a1 = 2.0 * (k * k - 1.0) * norm;
    section.a2 = (1.0 - k / q + k * k) * norm;
    sections_.push_back(section);
  }
  // Pad over 3 periods of the cut-off (the impulse response's decay), at least 3 N.
  pad_ = std::max(3 * order, static_cast<int>(std::ceil(3.0 * sample_rate / cutoff_frequency)));
}

double ZeroPhaseLowPass::Gain(double frequency) const {
  // Forward and backward passes give |H1(f)|^2, H1 one pass; for the bilinear
  // Butterworth |H1(f)|^2 = 1 / (1 + (tan(pi f / fs) / K)^(2N)).
  const double k = std::tan(M_PI * cutoff_frequency_ / sample_rate_);
  const double ratio = std::tan(M_PI * frequency / sample_rate_) / k;
  const int order = 2 * static_cast<int>(sections_.size());
  return 1.0 / (1.0 + std::pow(ratio, 2.0 * order));
}

void ZeroPhaseLowPass::FilterInPlace(std::vector<double>* values) const {
  std::vector<double>& x = *values;
  for (const Section& s : sections_) {
    // Direct form II transposed, started in the steady state of a constant input
    // x_0 (unit DC gain): s2 = (b2 - a2) x_0, s1 = (b1 - a1) x_0 + s2.
    double state2 = (s.b2 - s.a2) * x[0];
    double state1 = (s.b1 - s.a1) * x[0] + state2;
    for (double& value : x) {
      const double input = value;
      const double output = s.b0 * input + state1;
      state1 = s.b1 * input - s.a1 * output + state2;
      state2 = s.b2 * input - s.a2 * output;
      value = output;
    }
  }
}

namespace {

// Least-squares cubic q(k) = c0 + c1 k + c2 k^2 + c3 k^3 through x_0 .. x_{count-1}.
Eigen::Vector4d FitCubic(const double* x, int count, int stride) {
  Eigen::MatrixXd basis(count, 4);
  Eigen::VectorXd values(count);
  for (int k = 0; k < count; ++k) {
    const double t = k;
    basis.row(k) << 1.0, t, t * t, t * t * t;
    values[k] = x[k * stride];
  }
  return basis.colPivHouseholderQr().solve(values);
}

double Cubic(const Eigen::Vector4d& c, double k) {
  return c[0] + k * (c[1] + k * (c[2] + k * c[3]));
}

// Extends x beyond its first sample (stride +1, from x_0) or its last (stride -1,
// from x_{n-1}) by `pad` samples: the residual r = x - q from a local cubic q is
// reflected oddly, r(-k) = 2 r(0) - r(k), so value, slope and (up to the fit)
// curvature stay continuous at the junction. Writes extension[k - 1] = x(-k).
void ExtendEdge(const double* x, int stride, int pad, int fit_count, double* extension) {
  const Eigen::Vector4d q = FitCubic(x, fit_count, stride);
  const double r0 = x[0] - Cubic(q, 0.0);
  for (int k = 1; k <= pad; ++k) {
    const double rk = x[k * stride] - Cubic(q, k);
    extension[k - 1] = Cubic(q, -k) + 2.0 * r0 - rk;
  }
}

}  // namespace

Vector ZeroPhaseLowPass::Apply(const Vector& signal, bool at_rest_before_start) const {
  const int n = static_cast<int>(signal.size());
  if (n < 2) return signal;
  const int pad = std::min(pad_, n - 1);
  // The cubic is fitted over one period of the cut-off (at least 4 samples).
  const int fit_count =
      std::clamp(static_cast<int>(std::ceil(sample_rate_ / cutoff_frequency_)), 4, n);
  std::vector<double> extended(n + 2 * pad);
  std::vector<double> edge(pad);
  if (at_rest_before_start) {
    // x(-k) = 0: the rest state before t_0 (the sections then start at rest).
    std::fill(edge.begin(), edge.end(), 0.0);
  } else {
    ExtendEdge(signal.data(), +1, pad, fit_count, edge.data());
  }
  for (int k = 1; k <= pad; ++k) extended[pad - k] = edge[k - 1];
  for (int i = 0; i < n; ++i) extended[pad + i] = signal[i];
  ExtendEdge(signal.data() + n - 1, -1, pad, fit_count, edge.data());
  for (int k = 1; k <= pad; ++k) extended[pad + n - 1 + k] = edge[k - 1];
  // Forward pass, backward pass (zero phase).
  FilterInPlace(&extended);
  std::reverse(extended.begin(), extended.end());
  FilterInPlace(&extended);
  std::reverse(extended.begin(), extended.end());
  return Eigen::Map<const Vector>(extended.data() + pad, n);
}

double EstimateCutoffFrequency(const ChannelSet& measurements) {
  return EstimateCutoffFrequency(measurements.Values("fL"), measurements.time_step);
}

double EstimateCutoffFrequency(const Vector& load, double time_step) {
  const auto n = static_cast<int>(load.size());
  const double sample_rate = 1.0 / time_step;
  const double lowest = 2.0 / (time_step * std::max(n - 1, 1));
  const double highest = 0.45 * sample_rate;
  if (n < 64) return highest;
  // Periodogram of the load.
  Eigen::FFT<double> fft;
  std::vector<double> samples(load.data(), load.data() + n);
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, samples);
  const int bins = n / 2 + 1;
  std::vector<double> power(bins);
  for (int i = 0; i < bins; ++i) power[i] = std::norm(spectrum[i]);
  // White noise gives exponentially distributed bins: mean = median / ln 2, the
  // median taken over the upper half of the band where the load has no power.
  std::vector<double> upper(power.begin() + bins / 2, power.end());
  std::nth_element(upper.begin(), upper.begin() + upper.size() / 2, upper.end());
  const double noise_mean = upper[upper.size() / 2] / std::log(2.0);
  const auto peak_bin =
      static_cast<int>(std::max_element(power.begin(), power.end()) - power.begin());
  const double peak = power[peak_bin];
  const double threshold = std::max(kNoiseFactor * noise_mean, kDynamicRange * peak);
  // The load's band: from the peak up, the windows of kSmoothingBins bins whose mean
  // stands above the threshold, each within the band's own width of the band so far
  // (a gap of at most edge + kSmoothingBins bins): a pulse's side lobes lie closer
  // than its main lobe is wide, and a window of noise alone above the threshold far
  // above the band (rare for one window, but the band has hundreds) is left out.
  int edge = peak_bin;
  bool above = false;
  double window_sum = 0.0;
  for (int i = 0; i < bins; ++i) {
    window_sum += power[i];
    if (i >= kSmoothingBins) window_sum -= power[i - kSmoothingBins];
    const int count = std::min(i + 1, kSmoothingBins);
    if (!(window_sum / count > threshold)) continue;
    above = true;
    const int centre = i - count / 2;
    if (centre > edge && centre - edge <= edge + kSmoothingBins) edge = centre;
  }
  if (!above) edge = 0;
  const double frequency = edge * sample_rate / n;
  return std::clamp(kCutoffOverEdge * frequency, lowest, highest);
}

ChannelSet PrefilterMeasurements(const ChannelSet& measurements, const PrefilterOptions& options,
                                 double* cutoff_used) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  if (!options.enabled) return measurements;
  const double nyquist = 0.5 / measurements.time_step;
  if (!(options.cutoff_frequency < nyquist)) {
    std::ostringstream message;
    message << "prefilter.cutoff_frequency (" << options.cutoff_frequency
            << " Hz) must be below the Nyquist frequency of the measurements, 0.5 / time step = "
            << nyquist << " Hz (time step " << measurements.time_step << " s)";
    throw std::invalid_argument(message.str());
  }
  const double cutoff = options.cutoff_frequency > 0.0 ? options.cutoff_frequency
                                                       : EstimateCutoffFrequency(measurements);
  if (cutoff_used != nullptr) *cutoff_used = cutoff;
  const ZeroPhaseLowPass filter(cutoff, 1.0 / measurements.time_step, options.order);
  ChannelSet filtered = measurements;
  const bool rest = options.at_rest_before_start;
  for (Channel& channel : filtered.channels) channel.values = filter.Apply(channel.values, rest);
  return filtered;
}

}  // namespace mcrewave
