#include "mcrewave/model/bar_model.h"

#include <cassert>
#include <cmath>
#include <sstream>
#include <vector>

namespace mcrewave {

bool BarProperties::IsValid(std::string* error) const {
  std::ostringstream why;
  auto positive = [&why](double value, const char* name) {
    if (!(std::isfinite(value) && value > 0.0)) {
      why << name << " must be a finite positive number, got " << value;
      return false;
    }
    return true;
  };
  bool ok = positive(length, "model.length") && positive(section, "model.section") &&
            positive(density, "model.density") && positive(modulus, "model.modulus");
  if (ok && elements < 1) {
    why << "model.elements must be at least 1, got " << elements;
    ok = false;
  }
  if (!ok && error != nullptr) *error = why.str();
  return ok;
}

BarModel::BarModel(const BarProperties& properties) : properties_(properties) {
  assert(properties.IsValid(nullptr));
  const int n = num_nodes();
  const double he = element_length();
  const double rho_s = properties.density * properties.section;
  // Element matrices of a linear element of length h_e:
  //   M_e = rho S h_e / 6 [2 1; 1 2] (consistent) or rho S h_e / 2 I (lumped),
  //   K1_e = S / h_e [1 -1; -1 1].
  const double m_diag =
      properties.mass == MassType::kConsistent ? rho_s * he / 3.0 : rho_s * he / 2.0;
  const double m_off = properties.mass == MassType::kConsistent ? rho_s * he / 6.0 : 0.0;
  const double k = properties.section / he;

  std::vector<Eigen::Triplet<double>> m_entries, k_entries;
  m_entries.reserve(4 * properties.elements);
  k_entries.reserve(4 * properties.elements);
  for (int e = 0; e < properties.elements; ++e) {
    const int a = e, b = e + 1;
    m_entries.emplace_back(a, a, m_diag);
    m_entries.emplace_back(b, b, m_diag);
    k_entries.emplace_back(a, a, k);
    k_entries.emplace_back(b, b, k);
    k_entries.emplace_back(a, b, -k);
    k_entries.emplace_back(b, a, -k);
    if (m_off != 0.0) {
      m_entries.emplace_back(a, b, m_off);
      m_entries.emplace_back(b, a, m_off);
    }
  }
  mass_.resize(n, n);
  mass_.setFromTriplets(m_entries.begin(), m_entries.end());
  unit_stiffness_.resize(n, n);
  unit_stiffness_.setFromTriplets(k_entries.begin(), k_entries.end());
  boundary_selector_.resize(n, n);
  std::vector<Eigen::Triplet<double>> b_entries{{0, 0, 1.0}, {n - 1, n - 1, 1.0}};
  boundary_selector_.setFromTriplets(b_entries.begin(), b_entries.end());
}

double BarModel::WaveSpeed(double modulus) const {
  return std::sqrt(modulus / properties_.density);
}

}  // namespace mcrewave
