// The MCRE error map: where along the structure the constitutive relation is
// violated (docs/zones_and_sensors.md, "The error map").
//
// At a modulus field E_z and its coupled solution (U, W), the constitutive part of
// e^2 splits by element,
//
//   e^2_constitutive = sum_el e_el^2,   e_el^2 = sum_j c_j h 1/2 W_j^T K_el W_j  [J s],
//
// with K_el = E_el K1_el the element's stiffness. The elements whose modulus is wrong
// carry most of it: the map localises a stiffness change before any zone modulus is
// identified. The space-time picture is the gap's energy density per element and
// sample, 1/2 W_j^T K_el W_j / h_e [J/m], on at most max_time_columns samples and, on
// meshes of more than kMaxSpaceTimeColumns elements, averaged over groups of
// consecutive elements (SpaceTimeGroupSize).
#pragma once

#include "mcrewave/core/types.h"
#include "mcrewave/model/bar_model.h"

namespace mcrewave {

// Most samples and columns of the space-time picture.
constexpr int kSpaceTimeSamples = 160;
constexpr int kMaxSpaceTimeColumns = 2000;

struct ErrorMap {
  Vector position;  // element midpoints [m]
  Vector share;     // e_el^2 [J s], one per element
  // The space-time picture: density(i, c) = 1/2 W_ji^T K_el W_ji / h_e [J/m] at the
  // sample j_i of times(i) (every stride-th sample of the window), averaged over the
  // elements el of column c (one element per column up to kMaxSpaceTimeColumns).
  Vector times;             // [s]
  Vector density_position;  // column centres [m]
  Matrix density;           // times.size() x density_position.size()
  // The sensitivity map s_el = de^2/d ln E_el [J s], one per element, at the same
  // moduli (mcre/element_error_map.h): positive where lowering the element's modulus
  // lowers e^2, negative where raising it does. Empty when not computed.
  Vector sensitivity;

  // Index of the element with the largest share (-1 when empty).
  int PeakElement() const;
  // Index of the element with the largest sensitivity, where e^2 falls fastest as the
  // modulus is lowered (softening), and with the smallest, where it falls fastest as it
  // is raised (stiffening); -1 when the sensitivity is empty.
  int SofteningPeakElement() const;
  int StiffeningPeakElement() const;
  // share / sum(share): the fraction of the constitutive gap in each element.
  Vector Fractions() const;
};

// shares / sum(shares), zeros when the sum is not positive: the fraction of a
// constitutive gap in each part (element, zone, dof).
Vector GapFractions(const Vector& shares);

// The space-time picture's layout: every SpaceTimeStride-th of the m + 1 samples
// (at most max_time_columns >= 2 of them), and columns of SpaceTimeGroupSize
// consecutive elements (the last column may hold fewer), centred at
// SpaceTimeColumnPositions.
int SpaceTimeStride(int num_steps, int max_time_columns = kSpaceTimeSamples);
int SpaceTimeGroupSize(int num_elements);
Vector SpaceTimeColumnPositions(const BarModel& model);

// The map from its sums: the shares e_el^2 (one per element) and the picture's
// density (rows at every stride-th sample of steps time_step [s], columns on
// SpaceTimeColumnPositions), as a streaming solve gathers them.
ErrorMap AssembleErrorMap(const BarModel& model, const Vector& shares, const Matrix& density,
                          int stride, double time_step);

}  // namespace mcrewave
