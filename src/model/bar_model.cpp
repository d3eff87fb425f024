#include "mcrewave/model/bar_model.h"

#include <algorithm>
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
  if (ok &&
      !(std::isfinite(reaction_length) && reaction_length >= 0.0 && reaction_length <= length)) {
    why << "model.reaction_length must lie in [0, L = " << length << "] m, got " << reaction_length;
    ok = false;
  }
  // At most 1e8, so that node and entry counts stay far inside int.
  if (ok && (elements < 1 || elements > 100000000)) {
    why << "model.elements must be an integer in [1, 1e8], got " << elements;
    ok = false;
  }
  if (ok && coarse_elements != 0 && (coarse_elements < 10 || coarse_elements > 100000000)) {
    why << "model.coarse_elements must be 0 (one mesh) or an integer in [10, 1e8], got "
        << coarse_elements;
    ok = false;
  }
  if (!ok && error != nullptr) *error = why.str();
  return ok;
}

std::string ValidateModulusZones(const BarProperties& bar, const std::vector<ModulusZone>& zones,
                                 const std::string& key) {
  for (std::size_t i = 0; i < zones.size(); ++i) {
    const ModulusZone& zone = zones[i];
    std::ostringstream why;
    why << key << "[" << i << "]";
    if (!(std::isfinite(zone.start) && std::isfinite(zone.end) && zone.start >= 0.0 &&
          zone.end <= bar.length && zone.start < zone.end)) {
      why << " must satisfy 0 <= start < end <= L = " << bar.length << " m, got [" << zone.start
          << ", " << zone.end << "] m";
      return why.str();
    }
    if (!(std::isfinite(zone.modulus) && zone.modulus > 0.0)) {
      why << ".modulus must be a finite positive number [Pa], got " << zone.modulus;
      return why.str();
    }
    for (std::size_t k = 0; k < i; ++k) {
      if (zone.start < zones[k].end && zones[k].start < zone.end) {
        why << " [" << zone.start << ", " << zone.end << "] m overlaps " << key << "[" << k << "] ["
            << zones[k].start << ", " << zones[k].end << "] m";
        return why.str();
      }
    }
  }
  return "";
}

Vector ElementModuli(const BarProperties& bar, const std::vector<ModulusZone>& zones) {
  assert(ValidateModulusZones(bar, zones, "zones").empty());
  const int n = bar.elements;
  const double he = bar.length / n;
  Vector moduli(n);
  for (int e = 0; e < n; ++e) {
    const double a = e * he, b = (e + 1) * he;
    // Pieces of [a, b] in series: 1 / E_e = sum (length / h_e) / E_piece. Paint the
    // zones in order over the background, as breakpoints of the element.
    // Zone ends within 1e-9 h_e of a node are at the node (0.6 vs 6 x 0.1).
    const double tolerance = 1e-9 * he;
    std::vector<double> cuts{a, b};
    for (const ModulusZone& zone : zones) {
      for (double cut : {zone.start, zone.end}) {
        if (cut > a + tolerance && cut < b - tolerance) cuts.push_back(cut);
      }
    }
    std::sort(cuts.begin(), cuts.end());
    if (cuts.size() == 2) {
      // One piece: the element's modulus as it is (no round-off of a harmonic mean).
      double modulus = bar.modulus;
      for (const ModulusZone& zone : zones) {
        if (0.5 * (a + b) >= zone.start && 0.5 * (a + b) <= zone.end) modulus = zone.modulus;
      }
      moduli[e] = modulus;
      continue;
    }
    double compliance = 0.0;  // sum (length / h_e) / E_piece [1/Pa]
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
      const double length = cuts[c + 1] - cuts[c];
      if (length <= 0.0) continue;
      const double middle = 0.5 * (cuts[c] + cuts[c + 1]);
      double modulus = bar.modulus;
      for (const ModulusZone& zone : zones) {
        if (middle >= zone.start && middle <= zone.end) modulus = zone.modulus;
      }
      compliance += (length / he) / modulus;
    }
    moduli[e] = 1.0 / compliance;
  }
  return moduli;
}

std::vector<double> ZoneModuliInSeries(const BarModel& model, const Vector& element_moduli) {
  assert(element_moduli.size() == model.num_elements());
  std::vector<double> compliance(model.num_zones(), 0.0);
  std::vector<int> count(model.num_zones(), 0);
  for (int e = 0; e < model.num_elements(); ++e) {
    compliance[model.element_zone(e)] += 1.0 / element_moduli[e];
    ++count[model.element_zone(e)];
  }
  std::vector<double> moduli(model.num_zones());
  for (int z = 0; z < model.num_zones(); ++z) moduli[z] = count[z] / compliance[z];
  return moduli;
}

std::string ZoneLayout::Validate(const BarProperties& bar) const {
  std::ostringstream why;
  switch (zoning) {
    case Zoning::kEqual:
      if (zone_count < 1 || zone_count > bar.elements) {
        why << "model.zone_count must be between 1 and model.elements = " << bar.elements
            << " (every zone needs an element), got " << zone_count;
      }
      break;
    case Zoning::kPerElement:
      break;
    case Zoning::kGrid:
      if (zone_grid.size() != 1 || zone_grid[0] < 1 || zone_grid[0] > bar.elements) {
        why << "model.zone_grid must hold one count of zones along the bar, between 1 and "
               "model.elements = "
            << bar.elements << ", with model.zoning: grid on the bar";
      }
      break;
    case Zoning::kBoundaries: {
      if (zone_boundaries.empty()) {
        why << "model.zone_boundaries must list at least one interior boundary [m] with "
               "model.zoning: boundaries";
        break;
      }
      double previous = 0.0;
      for (std::size_t i = 0; i < zone_boundaries.size(); ++i) {
        const double b = zone_boundaries[i];
        if (!(std::isfinite(b) && b > previous && b < bar.length)) {
          why << "model.zone_boundaries[" << i << "] = " << b
              << " m: boundaries must increase strictly inside (0, L = " << bar.length << " m)";
          break;
        }
        previous = b;
      }
      if (!why.str().empty()) break;
      // Every zone must hold an element midpoint.
      const std::vector<int> zones = ElementZones(bar);
      std::vector<int> count(zone_boundaries.size() + 1, 0);
      for (int z : zones) ++count[z];
      for (std::size_t z = 0; z < count.size(); ++z) {
        if (count[z] == 0) {
          const double a = z == 0 ? 0.0 : zone_boundaries[z - 1];
          const double b = z == zone_boundaries.size() ? bar.length : zone_boundaries[z];
          why << "model.zone_boundaries: zone " << z << " [" << a << ", " << b
              << "] m holds no element midpoint (elements of " << bar.length / bar.elements
              << " m): widen it or refine model.elements";
          break;
        }
      }
      break;
    }
  }
  return why.str();
}

std::vector<int> ZoneLayout::ElementZones(const BarProperties& bar) const {
  const int n = bar.elements;
  const double he = bar.length / n;
  std::vector<int> zones(n, 0);
  for (int e = 0; e < n; ++e) {
    const double middle = (e + 0.5) * he;
    switch (zoning) {
      case Zoning::kEqual:
      case Zoning::kGrid: {
        // Zone z holds [z L / Z, (z + 1) L / Z): floor(Z x / L), clamped to Z - 1.
        const int count = zoning == Zoning::kGrid ? zone_grid[0] : zone_count;
        zones[e] = std::min(count - 1, static_cast<int>(std::floor(count * middle / bar.length)));
        break;
      }
      case Zoning::kPerElement:
        zones[e] = e;
        break;
      case Zoning::kBoundaries:
        zones[e] = static_cast<int>(
            std::upper_bound(zone_boundaries.begin(), zone_boundaries.end(), middle) -
            zone_boundaries.begin());
        break;
    }
  }
  return zones;
}

BarModel::BarModel(const BarProperties& properties)
    : BarModel(properties, std::vector<int>(properties.elements, 0)) {}

BarModel::BarModel(const BarProperties& properties, const std::vector<int>& element_zones)
    : properties_(properties), element_zones_(element_zones) {
  assert(properties.IsValid(nullptr));
  assert(static_cast<int>(element_zones.size()) == properties.elements);
  num_zones_ =
      element_zones.empty() ? 1 : *std::max_element(element_zones.begin(), element_zones.end()) + 1;
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

SparseMatrix BarModel::StiffnessOfElements(const Vector& element_moduli) const {
  assert(element_moduli.size() == num_elements());
  const int n = num_nodes();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(4 * num_elements());
  for (int e = 0; e < num_elements(); ++e) {
    // E_e K1_e = E_e k1_e [1 -1; -1 1] on nodes (e, e + 1).
    const double k = element_moduli[e] * element_unit_stiffness(e);
    entries.emplace_back(e, e, k);
    entries.emplace_back(e + 1, e + 1, k);
    entries.emplace_back(e, e + 1, -k);
    entries.emplace_back(e + 1, e, -k);
  }
  SparseMatrix stiffness(n, n);
  stiffness.setFromTriplets(entries.begin(), entries.end());
  return stiffness;
}

SparseMatrix BarModel::Stiffness(const Vector& zone_moduli) const {
  assert(zone_moduli.size() == num_zones());
  if (num_zones_ == 1) return Stiffness(zone_moduli[0]);
  Vector element_moduli(num_elements());
  for (int e = 0; e < num_elements(); ++e) element_moduli[e] = zone_moduli[element_zones_[e]];
  return StiffnessOfElements(element_moduli);
}

int BarModel::ElementAt(double position) const {
  assert(position >= 0.0 && position <= properties_.length);
  // x / h_e within 1e-9 below a node counts as the node (0.3 / 0.1 = 2.9999999999999996).
  const int e = static_cast<int>(std::floor(position / element_length() + 1e-9));
  return std::clamp(e, 0, num_elements() - 1);
}

ObservationRow BarModel::DisplacementRow(double position) const {
  const int e = ElementAt(position);
  // xi = (x - x_e) / h_e in [0, 1]; h = (1 - xi) e_e + xi e_{e+1}.
  const double xi = std::clamp(position / element_length() - e, 0.0, 1.0);
  ObservationRow row;
  row.nodes[0] = e;
  row.nodes[1] = e + 1;
  row.coefficients[0] = 1.0 - xi;
  row.coefficients[1] = xi;
  return row;
}

ObservationRow BarModel::StrainRow(double position) const {
  const double nodes_from_left = position / element_length();
  const int node = static_cast<int>(std::lround(nodes_from_left));
  ObservationRow row;
  if (node > 0 && node < num_elements() && std::abs(nodes_from_left - node) < 1e-9) {
    // A gauge on node i reads both its elements: h = (e_{i+1} - e_{i-1}) / (2 h_e), the
    // mean of their strains, exact at x_i for a quadratic field; one element's strain
    // is centred h_e / 2 away (docs/zones_and_sensors.md, "Sensors").
    row.nodes[0] = node - 1;
    row.nodes[1] = node + 1;
    row.coefficients[0] = -0.5 / element_length();
    row.coefficients[1] = 0.5 / element_length();
    return row;
  }
  const int e = ElementAt(position);
  // h = (e_{e+1} - e_e) / h_e.
  row.nodes[0] = e;
  row.nodes[1] = e + 1;
  row.coefficients[0] = -1.0 / element_length();
  row.coefficients[1] = 1.0 / element_length();
  return row;
}

double BarModel::WaveSpeed(double modulus) const {
  return std::sqrt(modulus / properties_.density);
}

SparseMatrix BarModel::ClampedBlock(const SparseMatrix& full) {
  const int n = static_cast<int>(full.rows());
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 1; j < n; ++j) {
    for (SparseMatrix::InnerIterator it(full, j); it; ++it) {
      if (it.row() >= 1) entries.emplace_back(it.row() - 1, j - 1, it.value());
    }
  }
  SparseMatrix block(n - 1, n - 1);
  block.setFromTriplets(entries.begin(), entries.end());
  return block;
}

}  // namespace mcrewave
