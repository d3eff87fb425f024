// How far apart the valleys of a data misfit lie along log E: the spacing the
// global scan of Identify (identification.h) must resolve (docs/global_search.md).
//
// Scheme. Along s = ln E the cost of noisy data is a smooth trend plus the
// correlation of the noise n(t) with the model's predicted outputs y(t; s),
//   g(s) = -2 sum_k w_k int_0^T n_k(t) y_k(t; s) dt,
// a Gaussian random function of s. A structure whose moduli all scale by e^s
// responds to a given load like itself with time scaled by e^{s/2} (its
// frequencies go as sqrt(E)), so dy/ds = (t/2) dy/dt, and for white noise the
// spectral moments of g are
//   lambda_2 = E[g'^2]  ~ sum_k w_k int (t/2)^2 |dy_k/dt|^2 dt,
//   lambda_4 = E[g''^2] ~ sum_k w_k int (t/2)^4 |d^2y_k/dt^2|^2 dt
// (the terms of highest order in t d/dt kept). Rice's formula gives the mean
// distance between neighbouring minima of g: 2 pi sqrt(lambda_2 / lambda_4).
// A mode of frequency f alone gives 2 / (sqrt(3/5) f T): the phase shift pi f T
// dE / E of the estimate, averaged over the window.
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
