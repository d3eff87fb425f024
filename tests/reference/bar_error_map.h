// The built-in bar's own error map, element by element from its band model: the tests'
// independent reference for the element maps of the one road (mcre/element_error_map.h)
// on the bar exported as matrices. The formulas are those of mcre/error_map.h, with the
// bar's element stiffness k1_el (W_{el+1} - W_el)^2 in place of the element blocks.
#pragma once

#include "mcrewave/core/types.h"
#include "mcrewave/mcre/error_map.h"
#include "mcrewave/model/bar_model.h"

namespace mcrewave {
namespace testing {

// shares[el] += weight 1/2 W_j^T K_el W_j for every element, from W_j (n entries).
void AddSampleGapShares(const BarModel& model, const Vector& zone_moduli, const double* retrograde,
                        double weight, Vector* shares);

// e_el^2 for every element (ErrorMap.share) of `model` at the zone moduli (one per
// zone) from the retrograde field W (n x (m + 1)) on steps of time_step [s].
Vector ElementGapShares(const BarModel& model, const Vector& zone_moduli, const Matrix& retrograde,
                        double time_step);

// row[c] = the mean over column c's elements of 1/2 W_j^T K_el W_j / h_e [J/m], from
// W_j (n entries); row holds SpaceTimeColumnPositions(model).size() entries.
void SampleGapDensity(const BarModel& model, const Vector& zone_moduli, const double* retrograde,
                      double* row);

// The whole map, with the space-time picture on at most max_time_columns samples.
// Precondition: max_time_columns >= 2.
ErrorMap ComputeErrorMap(const BarModel& model, const Vector& zone_moduli, const Matrix& retrograde,
                         double time_step, int max_time_columns = kSpaceTimeSamples);

}  // namespace testing
}  // namespace mcrewave
