#include "mcrewave/mcre/element_error_map.h"

#include <algorithm>
#include <cassert>

namespace mcrewave {

double ElementGapEnergy(const MatrixModelElement& element, const double* retrograde) {
  // 1/2 W_el^T K_el W_el = 1/2 (V^T K_el V + 2 c r^T V + c^2 1^T r), V = W_el - c 1,
  // r = K_el 1, c = W_{d_1} (element_error_map.h; docs/matrix_models.md section 2).
  const int k = static_cast<int>(element.dofs.size());
  const double shift = retrograde[element.dofs[0]];
  double quadratic = 0.0, linear = 0.0, constant = 0.0;
  for (int a = 0; a < k; ++a) {
    const double v_a = retrograde[element.dofs[a]] - shift;
    double row_product = 0.0, row_sum = 0.0;
    for (int b = 0; b < k; ++b) {
      row_product += element.stiffness(a, b) * (retrograde[element.dofs[b]] - shift);
      row_sum += element.stiffness(a, b);
    }
    quadratic += v_a * row_product;
    linear += row_sum * v_a;
    constant += row_sum;
  }
  return 0.5 * (quadratic + 2.0 * shift * linear + shift * shift * constant);
}

double ElementBilinearForm(const MatrixModelElement& element, const double* a, const double* b) {
  // a^T K_el b = V_a^T K_el V_b + c_b r^T V_a + c_a r^T V_b + c_a c_b 1^T r, V_x = x_el - c_x 1,
  // r = K_el 1, c_x = x_{d_1} (element_error_map.h).
  const int k = static_cast<int>(element.dofs.size());
  const double shift_a = a[element.dofs[0]], shift_b = b[element.dofs[0]];
  double quadratic = 0.0, linear_a = 0.0, linear_b = 0.0, constant = 0.0;
  for (int p = 0; p < k; ++p) {
    double row_product = 0.0, row_sum = 0.0;
    for (int q = 0; q < k; ++q) {
      row_product += element.stiffness(p, q) * (b[element.dofs[q]] - shift_b);
      row_sum += element.stiffness(p, q);
    }
    quadratic += (a[element.dofs[p]] - shift_a) * row_product;
    linear_a += row_sum * (a[element.dofs[p]] - shift_a);
    linear_b += row_sum * (b[element.dofs[p]] - shift_b);
    constant += row_sum;
  }
  return quadratic + shift_b * linear_a + shift_a * linear_b + shift_a * shift_b * constant;
}

namespace {

// E_z / E_z,nom of an element's zone.
double ZoneFactor(const MatrixModelData& model, const Vector& zone_moduli,
                  const MatrixModelElement& element) {
  return zone_moduli[element.zone] /
         model.zones[static_cast<std::size_t>(element.zone)].nominal_modulus;
}

}  // namespace

void AddSampleElementMaps(const MatrixModelData& model, const Vector& zone_moduli,
                          const double* displacement, const double* retrograde, double weight,
                          Vector* shares, Vector* sensitivities) {
  for (std::size_t el = 0; el < model.elements.size(); ++el) {
    const MatrixModelElement& element = model.elements[el];
    const double scale = weight * ZoneFactor(model, zone_moduli, element);
    const double gap = ElementGapEnergy(element, retrograde);
    const auto index = static_cast<Eigen::Index>(el);
    // weight (E_z / E_z,nom) 1/2 W_j^T K_el W_j.
    if (shares != nullptr) (*shares)[index] += scale * gap;
    // -weight (E_z / E_z,nom) (1/2 W_j^T K_el W_j + W_j^T K_el U_j).
    if (sensitivities != nullptr) {
      (*sensitivities)[index] -=
          scale * (gap + ElementBilinearForm(element, retrograde, displacement));
    }
  }
}

Vector MatrixElementGapShares(const MatrixModelData& model, const Vector& zone_moduli,
                              const Matrix& retrograde, double time_step) {
  assert(!model.elements.empty() &&
         zone_moduli.size() == static_cast<Eigen::Index>(model.zones.size()) &&
         retrograde.rows() == model.dofs());
  const int m = static_cast<int>(retrograde.cols()) - 1;
  Vector shares = Vector::Zero(static_cast<Eigen::Index>(model.elements.size()));
  for (int j = 0; j <= m; ++j) {
    // c_j h, c_j = 1/2 at both ends of the window.
    const double weight = (j == 0 || j == m ? 0.5 : 1.0) * time_step;
    AddSampleElementMaps(model, zone_moduli, nullptr, retrograde.col(j).data(), weight, &shares,
                         nullptr);
  }
  return shares;
}

Vector ElementMapPositions(const MatrixModelData& model) {
  Vector positions(static_cast<Eigen::Index>(model.elements.size()));
  for (std::size_t el = 0; el < model.elements.size(); ++el) {
    const Vector& position = model.elements[el].position;
    positions[static_cast<Eigen::Index>(el)] =
        position.size() > 0 ? position[0] : static_cast<double>(el);
  }
  return positions;
}

Vector ElementColumnPositions(const MatrixModelData& model) {
  const Vector positions = ElementMapPositions(model);
  const int elements = static_cast<int>(positions.size());
  const int group = SpaceTimeGroupSize(elements), columns = (elements + group - 1) / group;
  Vector centres(columns);
  for (int c = 0; c < columns; ++c) {
    const int first = c * group, end = std::min(elements, first + group);
    centres[c] = positions.segment(first, end - first).mean();
  }
  return centres;
}

void SampleElementGapDensity(const MatrixModelData& model, const Vector& zone_moduli,
                             const double* retrograde, double* row) {
  const int elements = static_cast<int>(model.elements.size());
  const int group = SpaceTimeGroupSize(elements);
  for (int first = 0, c = 0; first < elements; first += group, ++c) {
    const int end = std::min(elements, first + group);
    double sum = 0.0;
    for (int el = first; el < end; ++el) {
      // (E_z / E_z,nom) 1/2 W_j^T K_el W_j [J].
      const MatrixModelElement& element = model.elements[static_cast<std::size_t>(el)];
      sum += ZoneFactor(model, zone_moduli, element) * ElementGapEnergy(element, retrograde);
    }
    row[c] = sum / (end - first);
  }
}

ErrorMap ComputeElementErrorMap(const MatrixModelData& model, const Vector& zone_moduli,
                                const Matrix& retrograde, double time_step, int max_time_columns) {
  const int m = static_cast<int>(retrograde.cols()) - 1;
  const int stride = SpaceTimeStride(m, max_time_columns);
  Matrix density(m / stride + 1, ElementColumnPositions(model).size());
  Vector row(density.cols());
  for (int i = 0; i < density.rows(); ++i) {
    SampleElementGapDensity(model, zone_moduli, retrograde.col(i * stride).data(), row.data());
    density.row(i) = row.transpose();
  }
  return AssembleElementErrorMap(model,
                                 MatrixElementGapShares(model, zone_moduli, retrograde, time_step),
                                 density, m, time_step, max_time_columns);
}

ErrorMap AssembleElementErrorMap(const MatrixModelData& model, const Vector& shares,
                                 const Matrix& density, int num_steps, double time_step,
                                 int max_time_columns) {
  const int stride = SpaceTimeStride(num_steps, max_time_columns);
  ErrorMap map;
  map.position = ElementMapPositions(model);
  map.share = shares;
  map.density_position = ElementColumnPositions(model);
  assert(shares.size() == map.position.size() && density.rows() == num_steps / stride + 1 &&
         density.cols() == map.density_position.size());
  map.density = density;
  map.times.resize(density.rows());
  for (int i = 0; i < density.rows(); ++i) map.times[i] = (i * stride) * time_step;
  return map;
}

}  // namespace mcrewave
