// The finite-element model of the elastic bar (docs/discrete_mcre.md; zones and
// sensors: docs/zones_and_sensors.md).
//
// A bar x in [0, L] of section S and density rho, meshed with N linear elements
// of length h_e = L / N and N + 1 nodes numbered from x = 0; element e joins nodes
// e and e + 1. All nodes are kept: the clamp of the reference experiment is a
// boundary condition of the direct simulation only (ClampedBarSimulation); the
// MCRE model knows the ends only through the measured data.
//
// Zones. The modulus is piecewise constant over Z zones, each a set of elements:
//   K(E_1..E_Z) = sum_z E_z K1_z,   K1_z = sum_{e in z} K1_e,
// so that a new trial modulus costs no re-assembly of the element matrices. An
// element belongs to the zone that holds its midpoint (ZoneLayout). One zone (the
// default) is the paper's uniform bar, K = E K1.
//
// Sensors. An observation row h (H's row) reads a channel off the nodal
// displacements U: displacement at x in element e (local coordinate xi in [0, 1]):
// h = (1 - xi) e_e + xi e_{e+1}; axial strain at x inside element e: its strain,
// h = (e_{e+1} - e_e) / h_e; at an interior node i, the mean of its two elements'
// strains, h = (e_{i+1} - e_{i-1}) / (2 h_e) (a gauge straddling the node).
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

struct BarProperties {
  double length = 1.0;     // L [m]
  double section = 1e-4;   // S [m^2]
  double density = 800.0;  // rho [kg/m^3]
  double modulus = 200e9;  // E [Pa], the reference (or initial) modulus
  int elements = 100;      // N, number of linear elements
  MassType mass = MassType::kConsistent;
  // a [m]: the clamp's reaction, where the clamp is trusted, is the axial force averaged
  // over [0, a] (at least the first element; docs/boundaries.md section 7). A fixed
  // length keeps the reaction's gain, and the inner solves' iterations, independent of
  // the mesh. 0: the first element.
  double reaction_length = 0.01;
  // The coarse mesh of the bar's identification on two meshes (docs/multilevel.md): when
  // `elements` exceeds it, the MCRE identification runs first on a bar of this many
  // elements with the same data, then refines E on `elements` from there. 0: one mesh.
  int coarse_elements = 1000;

  // True when every value is usable; otherwise writes the reason to *error.
  bool IsValid(std::string* error) const;
};

// A stretch [start, end] of the bar [m] with its own modulus [Pa]: the truth's
// heterogeneities of synthetic data (data.truth_zones), over the modulus of
// BarProperties elsewhere.
struct ModulusZone {
  double start = 0.0;    // [m]
  double end = 0.0;      // [m]
  double modulus = 0.0;  // [Pa]
};

// The moduli of the N elements of `bar` [Pa] under the zones (which do not overlap).
// An element partly covered gets the modulus of its pieces in series,
// 1 / E_e = sum_pieces (length / h_e) / E_piece, which keeps the element's static axial
// stiffness exact. Precondition: the zones are valid for the bar (ValidateModulusZones).
Vector ElementModuli(const BarProperties& bar, const std::vector<ModulusZone>& zones);

class BarModel;
// The modulus of each zone of `model` [Pa] that gives its elements (of moduli
// `element_moduli` [Pa], one per element) in series the same compliance: 1 / E_z = mean
// over the zone's elements of 1 / E_e (the elements of a bar have equal lengths). The
// truth's modulus of a zone, as zones.csv and the damage study report it.
std::vector<double> ZoneModuliInSeries(const BarModel& model, const Vector& element_moduli);
// Empty when every zone lies in [0, L] with start < end and a finite positive
// modulus, and no two zones overlap; otherwise the reason, naming zone i as `key`[i].
std::string ValidateModulusZones(const BarProperties& bar, const std::vector<ModulusZone>& zones,
                                 const std::string& key);

// The identification's zones: which zone each element belongs to. On the bar every
// zoning applies; on a structure given by matrices the default (kEqual with one zone)
// keeps the manifest's zones, and kPerElement and kGrid regroup its element blocks
// (RezonedMatrixModel, model/matrix_model_elements.h).
struct ZoneLayout {
  Zoning zoning = Zoning::kEqual;
  int zone_count = 1;                   // kEqual: Z zones of equal length
  std::vector<double> zone_boundaries;  // kBoundaries: interior boundaries [m], increasing
  // kGrid: boxes per coordinate of the elements' positions (1 to 3 counts); on the bar
  // one count Z, the same zones as kEqual with Z.
  std::vector<int> zone_grid;
  // kPerElement, kGrid on a matrix model: the zones (by name) that keep a modulus of
  // their own; every other zone of the layout is tied into one zone "rest" (a
  // localise-then-update refit, docs/matrix_models.md section 15). Empty: every zone free.
  std::vector<std::string> free_zones;

  // True when the layout regroups a matrix model's elements (kPerElement, kGrid).
  bool RegroupsElements() const { return zoning == Zoning::kPerElement || zoning == Zoning::kGrid; }
  // Empty when the layout is usable on `bar` (every zone holds at least one element,
  // boundaries strictly inside (0, L) and increasing, one grid count); otherwise the
  // reason, naming the keys model.zoning, model.zone_count, model.zone_boundaries,
  // model.zone_grid.
  std::string Validate(const BarProperties& bar) const;
  // The zone of each element, by its midpoint: zone z holds the elements whose
  // midpoint lies in [b_z, b_{z+1}) (the last zone up to L inclusive), b_0 = 0,
  // b_Z = L; kEqual: b_z = z L / Z (kGrid: Z = zone_grid[0]); kPerElement: zone e =
  // element e. Precondition: Validate(bar) is empty.
  std::vector<int> ElementZones(const BarProperties& bar) const;
};

// One row of the observation operator H: a channel is
// coefficients[0] U[nodes[0]] + coefficients[1] U[nodes[1]].
struct ObservationRow {
  int nodes[2] = {0, 0};
  double coefficients[2] = {0.0, 0.0};
  double Apply(const double* displacement) const {
    return coefficients[0] * displacement[nodes[0]] + coefficients[1] * displacement[nodes[1]];
  }
};

class BarModel {
 public:
  // Assembles M and the K1_z of one zone (the whole bar). Precondition:
  // properties.IsValid().
  explicit BarModel(const BarProperties& properties);
  // Assembles M and K1_z for the zones of `element_zones` (one entry per element,
  // zones numbered 0..Z-1, each holding at least one element).
  BarModel(const BarProperties& properties, const std::vector<int>& element_zones);

  const BarProperties& properties() const { return properties_; }
  int num_elements() const { return properties_.elements; }
  int num_nodes() const { return properties_.elements + 1; }
  double element_length() const { return properties_.length / properties_.elements; }  // [m]
  int left_node() const { return 0; }                                                  // x = 0
  int right_node() const { return properties_.elements; }                              // x = L

  // Mass matrix M [kg], symmetric positive definite, tridiagonal.
  const SparseMatrix& mass() const { return mass_; }
  // Stiffness per unit modulus K1 [m] (K = E K1 [N/m]), symmetric, tridiagonal,
  // kernel = rigid translations.
  const SparseMatrix& unit_stiffness() const { return unit_stiffness_; }
  // K = modulus * K1 [N/m], every zone at the same modulus.
  SparseMatrix Stiffness(double modulus) const { return modulus * unit_stiffness_; }
  // K = sum_z E_z K1_z [N/m]; zone_moduli has num_zones() entries [Pa].
  SparseMatrix Stiffness(const Vector& zone_moduli) const;
  // K = sum_e E_e K1_e [N/m] from a modulus per element [Pa] (num_elements() entries).
  SparseMatrix StiffnessOfElements(const Vector& element_moduli) const;

  int num_zones() const { return num_zones_; }
  // Zone of element e, in [0, num_zones()).
  int element_zone(int element) const { return element_zones_[element]; }
  const std::vector<int>& element_zones() const { return element_zones_; }
  // The axial stiffness per unit modulus of element e, k1_e = S / h_e [m] (the same for
  // every element: the mesh is uniform): K1_e = k1_e [1 -1; -1 1] on nodes (e, e + 1).
  double element_unit_stiffness([[maybe_unused]] int element) const {
    return properties_.section / element_length();
  }
  // x of the midpoint of element e [m].
  double element_midpoint(int element) const { return (element + 0.5) * element_length(); }
  // x of node i [m].
  double node_position(int node) const { return node * element_length(); }

  // The element that holds x in [0, L]: floor(x / h_e), the last element for x = L
  // (a node shared by two elements belongs to the one on its right; x within 1e-9 h_e
  // below a node counts as the node).
  int ElementAt(double position) const;
  // Observation rows (see the file comment). Precondition: 0 <= x <= L. StrainRow
  // counts x within 1e-9 h_e of an interior node as the node.
  ObservationRow DisplacementRow(double position) const;
  ObservationRow StrainRow(double position) const;
  // B = e_0 e_0^T + e_N e_N^T, the selector of the two measured end nodes.
  const SparseMatrix& boundary_selector() const { return boundary_selector_; }

  // Wave speed c = sqrt(E / rho) [m/s] for a given modulus.
  double WaveSpeed(double modulus) const;

  // The rows and columns of the free nodes 1..N of a matrix over every node: the
  // bar clamped at x = 0 (node 0 removed).
  static SparseMatrix ClampedBlock(const SparseMatrix& full);

 private:
  BarProperties properties_;
  int num_zones_ = 1;
  std::vector<int> element_zones_;
  SparseMatrix mass_;
  SparseMatrix unit_stiffness_;
  SparseMatrix boundary_selector_;
};

}  // namespace mcrewave
