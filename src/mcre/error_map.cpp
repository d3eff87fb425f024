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

Vector GapFractions(const Vector& shares) {
  const double total = shares.sum();
  return total > 0.0 ? Vector(shares / total) : Vector(Vector::Zero(shares.size()));
}

Vector ErrorMap::Fractions() const { return GapFractions(share); }

void AddSampleGapShares(const BarModel& model, const Vector& zone_moduli, const double* retrograde,
                        double weight, Vector* shares) {
  for (int e = 0; e < model.num_elements(); ++e) {
    // 1/2 W_j^T K_el W_j = 1/2 E_el k1_el (W_{el+1} - W_el)^2.
    const double jump = retrograde[e + 1] - retrograde[e];
    (*shares)[e] += weight * 0.5 * zone_moduli[model.element_zone(e)] *
                    model.element_unit_stiffness(e) * jump * jump;
  }
}

Vector ElementGapShares(const BarModel& model, const Vector& zone_moduli, const Matrix& retrograde,
                        double time_step) {
  assert(zone_moduli.size() == model.num_zones() && retrograde.rows() == model.num_nodes());
  const int m = static_cast<int>(retrograde.cols()) - 1;
  Vector shares = Vector::Zero(model.num_elements());
  for (int j = 0; j <= m; ++j) {
    // c_j h, c_j = 1/2 at both ends of the window.
    const double weight = (j == 0 || j == m ? 0.5 : 1.0) * time_step;
    AddSampleGapShares(model, zone_moduli, retrograde.col(j).data(), weight, &shares);
  }
  return shares;
}

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

void SampleGapDensity(const BarModel& model, const Vector& zone_moduli, const double* retrograde,
                      double* row) {
  const int elements = model.num_elements(), group = SpaceTimeGroupSize(elements);
  for (int first = 0, c = 0; first < elements; first += group, ++c) {
    const int end = std::min(elements, first + group);
    double sum = 0.0;
    for (int e = first; e < end; ++e) {
      // 1/2 W_j^T K_el W_j / h_e = 1/2 E_el k1_el (W_{el+1} - W_el)^2 / h_e [J/m].
      const double jump = retrograde[e + 1] - retrograde[e];
      sum += 0.5 * zone_moduli[model.element_zone(e)] * model.element_unit_stiffness(e) * jump *
             jump / model.element_length();
    }
    row[c] = sum / (end - first);
  }
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

ErrorMap ComputeErrorMap(const BarModel& model, const Vector& zone_moduli, const Matrix& retrograde,
                         double time_step, int max_time_columns) {
  const int m = static_cast<int>(retrograde.cols()) - 1;
  const int stride = SpaceTimeStride(m, max_time_columns);
  Matrix density(m / stride + 1, SpaceTimeColumnPositions(model).size());
  Vector row(density.cols());
  for (int i = 0; i < density.rows(); ++i) {
    SampleGapDensity(model, zone_moduli, retrograde.col(i * stride).data(), row.data());
    density.row(i) = row.transpose();
  }
  return AssembleErrorMap(model, ElementGapShares(model, zone_moduli, retrograde, time_step),
                          density, stride, time_step);
}

}  // namespace mcrewave
