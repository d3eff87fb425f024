#include "mcrewave/mcre/error_map.h"

#include <algorithm>
#include <cassert>

namespace mcrewave {
namespace {

// 1/2 W_j^T K_el W_j = 1/2 E_el k1_el (W_{el+1} - W_el)^2 [J], for element el at sample j.
double ElementGap(const BarModel& model, const Vector& zone_moduli, const Matrix& retrograde,
                  int element, int j) {
  const double jump = retrograde(element + 1, j) - retrograde(element, j);
  return 0.5 * zone_moduli[model.element_zone(element)] * model.element_unit_stiffness(element) *
         jump * jump;
}

}  // namespace

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

ErrorMap ComputeErrorMap(const BarModel& model, const Vector& zone_moduli, const Matrix& retrograde,
                         double time_step, int max_time_columns) {
  assert(max_time_columns >= 2);
  ErrorMap map;
  const int elements = model.num_elements();
  map.position.resize(elements);
  for (int e = 0; e < elements; ++e) map.position[e] = model.element_midpoint(e);
  map.share = ElementGapShares(model, zone_moduli, retrograde, time_step);
  const int m = static_cast<int>(retrograde.cols()) - 1;
  // Every stride-th sample, stride = ceil(m / (max_time_columns - 1)).
  const int stride = std::max(1, (m + max_time_columns - 2) / (max_time_columns - 1));
  const int rows = m / stride + 1;
  map.times.resize(rows);
  map.density.resize(rows, elements);
  for (int i = 0; i < rows; ++i) {
    const int j = i * stride;
    map.times[i] = j * time_step;
    for (int e = 0; e < elements; ++e) {
      map.density(i, e) = ElementGap(model, zone_moduli, retrograde, e, j) / model.element_length();
    }
  }
  return map;
}

}  // namespace mcrewave
