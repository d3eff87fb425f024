// The MCRE error map per element of a structure given by matrices with element blocks
// (MatrixModelData::elements; docs/matrix_models.md section 2, "The error map"): the
// bar's map (mcre/error_map.h) for any structure.
//
// At zone moduli E_z and the retrograde field W of a coupled solution, the constitutive
// part of e^2 splits by element,
//
//   e_el^2 = (E_z / E_z,nom) sum_j c_j h 1/2 W_j^T K_el W_j  [J s],
//
// W_j restricted to the element's dofs, K_el its block at the zone's nominal modulus
// (z its zone). The blocks of a zone sum to K_z, so the elements' shares sum to the
// zones' (MatrixMcreProblem::ZoneErrorMap). Each quadratic form is taken about the
// element's first dof value c = W_{d_1}: with V = W_el - c 1 and r = K_el 1,
//
//   W_el^T K_el W_el = V^T K_el V + 2 c r^T V + c^2 1^T r,
//
// the same number in exact arithmetic, without the cancellation of a smooth W where
// K_el's rows sum to zero (r = 0: a bar or scalar-field element, whose gap is then
// E k1 (W_b - W_a)^2 as the bar computes it).
//
// The space-time picture (ErrorMap::density) is the gap energy at a sample,
// (E_z / E_z,nom) 1/2 W_j^T K_el W_j [J] (per element, not per length: a matrix model
// has no element length; the bar's density is this over h_e), on every stride-th
// sample (SpaceTimeStride) and averaged over columns of SpaceTimeGroupSize consecutive
// elements (in the model's order). ErrorMap::position is each element's first
// coordinate [m] (its index when the elements have no positions) and
// ErrorMap::density_position each column's mean of them.
//
// The sensitivity map (ErrorMap::sensitivity) is the zone gradient
// (MatrixMcreProblem::CostGradients) split by element and taken in log E: with every
// element its own modulus, each at its zone's E_z,
//
//   s_el = de^2/d ln E_el
//        = -(E_z / E_z,nom) sum_j c_j h (1/2 W_j^T K_el W_j + W_j^T K_el U_j)  [J s],
//
// plus, under a trusted treatment, the reactions' part
// (E_z / E_z,nom) sum_j c_j h alpha_r sum_s (r_s(U_j) - f~_sj) phi_s^T K_el U_j. The
// elements of zone z sum to E_z de^2/dE_z. s_el > 0 where lowering the element's
// modulus lowers e^2 (the model too stiff there), s_el < 0 where raising it does
// (docs/boundaries.md section 11). The cross form W^T K_el U is shifted like the gap's,
// each vector about its own first dof value.
#pragma once

#include "mcrewave/core/types.h"
#include "mcrewave/mcre/error_map.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {

// 1/2 W_el^T K_el W_el of one element at its zone's nominal modulus [J], from W_j (the
// model's n entries), by the shifted form above. No allocation.
double ElementGapEnergy(const MatrixModelElement& element, const double* retrograde);

// a_el^T K_el b_el of one element at its zone's nominal modulus [J per unit of a and b],
// from the model's n-entry vectors a and b, by the shifted form above (a about a_{d_1},
// b about b_{d_1}). No allocation.
double ElementBilinearForm(const MatrixModelElement& element, const double* a, const double* b);

// The gap shares and the sensitivity's field part of one sample, from U_j and W_j:
//   shares[el] += weight (E_z / E_z,nom) 1/2 W_j^T K_el W_j,
//   sensitivities[el] -= weight (E_z / E_z,nom) (1/2 W_j^T K_el W_j + W_j^T K_el U_j).
// zone_moduli has one entry per zone [Pa]; shares and sensitivities one per element.
// Either may be null; displacement is read only for the sensitivities. No allocation.
void AddSampleElementMaps(const MatrixModelData& model, const Vector& zone_moduli,
                          const double* displacement, const double* retrograde, double weight,
                          Vector* shares, Vector* sensitivities);

// e_el^2 for every element [J s] at the zone moduli from W (n x (m + 1)) on steps of
// time_step [s]. Precondition: the model has elements.
Vector MatrixElementGapShares(const MatrixModelData& model, const Vector& zone_moduli,
                              const Matrix& retrograde, double time_step);

// ErrorMap::position of the model's elements (above).
Vector ElementMapPositions(const MatrixModelData& model);

// The picture's column centres: each column's mean of ElementMapPositions.
Vector ElementColumnPositions(const MatrixModelData& model);

// row[c] = the mean over column c's elements of (E_z / E_z,nom) 1/2 W_j^T K_el W_j [J]
// from W_j; row holds ElementColumnPositions(model).size() entries. No allocation.
void SampleElementGapDensity(const MatrixModelData& model, const Vector& zone_moduli,
                             const double* retrograde, double* row);

// The whole map: shares, positions and the space-time picture on at most
// max_time_columns samples. Preconditions: the model has elements, max_time_columns >= 2.
ErrorMap ComputeElementErrorMap(const MatrixModelData& model, const Vector& zone_moduli,
                                const Matrix& retrograde, double time_step,
                                int max_time_columns = kSpaceTimeSamples);

// The same map from the element shares and the picture's rows a streaming solve summed
// (StreamingCoupledProblem::StreamingTotals: element_error_map, gap_density on every
// stride-th sample, stride = SpaceTimeStride(num_steps, max_time_columns));
// ComputeElementErrorMap assembles its map here too. Preconditions: the model has
// elements, shares one per element, density of the picture's shape.
ErrorMap AssembleElementErrorMap(const MatrixModelData& model, const Vector& shares,
                                 const Matrix& density, int num_steps, double time_step,
                                 int max_time_columns = kSpaceTimeSamples);

}  // namespace mcrewave
