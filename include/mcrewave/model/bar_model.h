// The finite-element model of the elastic bar (formulation.md sections 1 and 3).
//
// A bar x in [0, L] of section S and density rho, meshed with N linear elements
// of length h_e = L / N and N + 1 nodes numbered from x = 0. All nodes are kept:
// the clamp of the reference experiment is a boundary condition of the direct
// simulation only (ClampedBarSimulation); the MCRE model knows the ends only
// through the measured data. The stiffness is K = E K1 so that a new trial
// modulus costs no re-assembly.
#pragma once

#include "mcrewave/core/types.h"

namespace mcrewave {

struct BarProperties {
  double length = 1.0;     // L [m]
  double section = 1e-4;   // S [m^2]
  double density = 800.0;  // rho [kg/m^3]
  double modulus = 200e9;  // E [Pa], the reference (or initial) modulus
  int elements = 100;      // N, number of linear elements
  MassType mass = MassType::kConsistent;

  // True when every value is usable; otherwise writes the reason to *error.
  bool IsValid(std::string* error) const;
};

class BarModel {
 public:
  // Assembles M and K1. Precondition: properties.IsValid().
  explicit BarModel(const BarProperties& properties);

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
  // K = modulus * K1 [N/m].
  SparseMatrix Stiffness(double modulus) const { return modulus * unit_stiffness_; }
  // B = e_0 e_0^T + e_N e_N^T, the selector of the two measured end nodes.
  const SparseMatrix& boundary_selector() const { return boundary_selector_; }

  // Wave speed c = sqrt(E / rho) [m/s] for a given modulus.
  double WaveSpeed(double modulus) const;

 private:
  BarProperties properties_;
  SparseMatrix mass_;
  SparseMatrix unit_stiffness_;
  SparseMatrix boundary_selector_;
};

}  // namespace mcrewave
