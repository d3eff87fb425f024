#include "reference/bar_error_map.h"

#include <algorithm>
#include <cassert>

namespace mcrewave {
namespace testing {

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

}  // namespace testing
}  // namespace mcrewave
