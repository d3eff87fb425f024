#include "mcrewave/optim/valley_spacing.h"

#include <cassert>
#include <cmath>

namespace mcrewave {

double PredictedValleySpacing(const Matrix& traces, const Vector& weights, double time_step) {
  assert(weights.size() == traces.rows());
  assert(time_step > 0.0);
  const int m = static_cast<int>(traces.cols()) - 1;
  if (m < 2) return 0.0;
  double lambda_2 = 0.0;
  double lambda_4 = 0.0;
  for (int k = 0; k < traces.rows(); ++k) {
    if (!(weights[k] > 0.0)) continue;
    double first = 0.0;
    double second = 0.0;
    for (int j = 1; j < m; ++j) {
      const double half_time = 0.5 * j * time_step;
      // y' = (y_{j+1} - y_{j-1}) / (2 h),  y'' = (y_{j+1} - 2 y_j + y_{j-1}) / h^2
      const double rate = (traces(k, j + 1) - traces(k, j - 1)) / (2.0 * time_step);
      const double curvature =
          (traces(k, j + 1) - 2.0 * traces(k, j) + traces(k, j - 1)) / (time_step * time_step);
      const double t2 = half_time * half_time;
      first += t2 * rate * rate;
      second += t2 * t2 * curvature * curvature;
    }
    lambda_2 += weights[k] * first;
    lambda_4 += weights[k] * second;
  }
  if (!(lambda_2 > 0.0 && lambda_4 > 0.0) || !std::isfinite(lambda_2 / lambda_4)) return 0.0;
  // 2 pi sqrt(lambda_2 / lambda_4): Rice's mean distance between minima.
  return 2.0 * M_PI * std::sqrt(lambda_2 / lambda_4);
}

}  // namespace mcrewave
