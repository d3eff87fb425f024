#include "mcrewave/model/experiment.h"

#include <cmath>
#include <sstream>

namespace mcrewave {
namespace {

bool Fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

bool FinitePositive(double value) { return std::isfinite(value) && value > 0.0; }

}  // namespace

bool LoadOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!std::isfinite(amplitude)) {
    why << "load.amplitude must be a finite number, got " << amplitude;
    return Fail(error, why.str());
  }
  if (!FinitePositive(duration)) {
    why << "load.duration must be a finite positive number of seconds, got " << duration;
    return Fail(error, why.str());
  }
  return true;
}

double LoadOptions::Value(double time) const {
  // Half sine: F(t) = F0 sin(pi t / t_load) on [0, t_load], 0 elsewhere.
  if (time < 0.0 || time > duration) return 0.0;
  return amplitude * std::sin(M_PI * time / duration);
}

bool TimeOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!FinitePositive(window)) {
    why << "time.window must be a finite positive number of seconds, got " << window;
    return Fail(error, why.str());
  }
  if (!FinitePositive(step)) {
    why << "time.step must be a finite positive number of seconds, got " << step;
    return Fail(error, why.str());
  }
  if (!(theta >= 0.0 && theta <= 1.0)) {
    why << "time.theta must lie in [0, 1], got " << theta;
    return Fail(error, why.str());
  }
  const double ratio = window / step;
  if (ratio > 1e8) {
    why << "time.window / time.step = " << ratio << " steps, more than the limit of 1e8";
    return Fail(error, why.str());
  }
  if (ratio < 1.0 - 1e-9 || std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    why << "time.window (" << window << " s) must hold a whole number of time.step (" << step
        << " s); the ratio is " << ratio;
    return Fail(error, why.str());
  }
  return true;
}

int TimeOptions::NumSteps() const { return static_cast<int>(std::lround(window / step)); }

bool DataOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (source == DataSource::kCsv && path.empty()) {
    return Fail(error, "data.path must name a measurement CSV file when data.source is csv");
  }
  if (truth_refinement < 1 || truth_refinement > 64) {
    why << "data.truth_refinement must be an integer in [1, 64], got " << truth_refinement;
    return Fail(error, why.str());
  }
  if (!(snr > 0.0)) {
    why << "data.snr must be positive (.inf for no noise), got " << snr;
    return Fail(error, why.str());
  }
  return true;
}

}  // namespace mcrewave
