// How far apart the valleys of a data misfit lie along log E: the spacing the global
// scan of Identify (identification.h) must resolve. Scheme (docs/global_search.md
// section 1): along s = ln E the noise's share of the cost is a Gaussian random function
// of s; with dy/ds = (t/2) dy/dt (a structure whose moduli scale by e^s runs its
// response faster by e^{s/2}), Rice's formula gives the mean distance between its
// neighbouring minima, 2 pi sqrt(lambda_2 / lambda_4), from the spectral moments below.
#pragma once

#include "mcrewave/core/types.h"

namespace mcrewave {

// The predicted mean spacing, in ln E, of the local minima of a misfit of the
// outputs `traces` (one row per channel, one column per sample t_j = j
// time_step [s], j = 0..m) weighted per channel by weights (>= 0, one per row):
//   2 pi sqrt(sum_k w_k sum_j (t_j/2)^2 |y'_kj|^2 / sum_k w_k sum_j (t_j/2)^4 |y''_kj|^2),
// with central differences y' and y'' at the interior samples. 0 when it cannot
// be told (fewer than 3 samples, or outputs without curvature).
double PredictedValleySpacing(const Matrix& traces, const Vector& weights, double time_step);

}  // namespace mcrewave
