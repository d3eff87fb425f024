#include "mcrewave/mcre/error_map.h"

#include <algorithm>
#include <cassert>

namespace mcrewave {

int ErrorMap::PeakElement() const {
  if (share.size() == 0) return -1;
  Eigen::Index peak = 0;
  share.maxCoeff(&peak);
  return static_cast<int>(peak);
}

int ErrorMap::SofteningPeakElement() const {
  if (sensitivity.size() == 0) return -1;
  Eigen::Index peak = 0;
  sensitivity.maxCoeff(&peak);
  return static_cast<int>(peak);
}

int ErrorMap::StiffeningPeakElement() const {
  if (sensitivity.size() == 0) return -1;
  Eigen::Index peak = 0;
  sensitivity.minCoeff(&peak);
  return static_cast<int>(peak);
}

Vector GapFractions(const Vector& shares) {
  const double total = shares.sum();
  return total > 0.0 ? Vector(shares / total) : Vector(Vector::Zero(shares.size()));
}

Vector ErrorMap::Fractions() const { return GapFractions(share); }

int SpaceTimeStride(int num_steps, int max_time_columns) {
  assert(max_time_columns >= 2 && num_steps >= 0);
  // stride = ceil(m / (max_time_columns - 1)), at least 1.
  return std::max(1, (num_steps + max_time_columns - 2) / (max_time_columns - 1));
}

int SpaceTimeGroupSize(int num_elements) {
  // ceil(elements / kMaxSpaceTimeColumns).
  return (num_elements + kMaxSpaceTimeColumns - 1) / kMaxSpaceTimeColumns;
}

Vector SpaceTimeColumnPositions(const BarModel& model) {
  const int elements = model.num_elements(), group = SpaceTimeGroupSize(elements);
  const int columns = (elements + group - 1) / group;
  Vector positions(columns);
  for (int c = 0; c < columns; ++c) {
    // Midway between the first and the last element's midpoints.
    const int last = std::min(elements, (c + 1) * group) - 1;
    positions[c] = 0.5 * (model.element_midpoint(c * group) + model.element_midpoint(last));
  }
  return positions;
}

ErrorMap AssembleErrorMap(const BarModel& model, const Vector& shares, const Matrix& density,
                          int stride, double time_step) {
  assert(shares.size() == model.num_elements() && stride >= 1);
  ErrorMap map;
  map.position.resize(model.num_elements());
  for (int e = 0; e < model.num_elements(); ++e) map.position[e] = model.element_midpoint(e);
  map.share = shares;
  map.density_position = SpaceTimeColumnPositions(model);
  map.density = density;
  map.times.resize(density.rows());
  for (int i = 0; i < density.rows(); ++i) map.times[i] = (i * stride) * time_step;
  return map;
}

}  // namespace mcrewave
