// Multiply-accumulate (MAC) counts of the kernels the coupled solvers are built from,
// following the loops of mcrewave's kernels (band products and LDL^T solves, theta
// steps, sweeps) and the textbook counts of the dense algorithms Eigen runs. One MAC is
// one multiplication with the addition that follows it; a division counts as one, a
// lone addition or a copy as none. The convention and the resulting per-method costs:
// docs/riccati_shooting.md section 4.
#pragma once

namespace mcrewave::operation_counts {

// y = A x, A symmetric n x n with half bandwidth p: every stored entry of the full
// band, n (2p + 1) - p (p + 1) MACs (3n - 2 for a tridiagonal matrix).
double BandProduct(int n, int p);

// x = A^-1 b from the LDL^T factors of a band matrix: L y = b and L^T x = z touch the
// n p - p (p + 1) / 2 entries of L once each, z = D^-1 y one MAC per row.
double BandSolve(int n, int p);

// y += alpha A x: the band product and the n scalings by alpha.
double BandProductAdd(int n, int p);

// One theta step (theta_integrator.h): rhs = R v - h K u (+ h f), S v' = rhs,
// u' = u + h (1 - theta) v + h theta v': two band products, the scaling by h of
// K u (n), the solve and the update (2n). with_force adds the n MACs of h f.
double ThetaStep(int n, int p, bool with_force);

// One direct sweep of the paper's bar as a band model loaded at its two end nodes
// (m steps, n nodes): per time level the force
// g_j = F~_j - (K + B/alpha) W_j (a band product and 2 end entries), per step the
// theta weighting of the force (2n) and one theta step with force.
double DirectSweep(int n, int p, int m);

// One retrograde sweep of that band model: per step the 2 end-node forces and a theta
// step with force, per time level W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j
// (3n, the division by c_j included).
double RetrogradeSweep(int n, int p, int m);

// One inner product <x, y>_P = sum_j c_j h x_j^T (K + B/alpha) y_j over the m + 1
// time levels: a band product, a dot product and the end and weight terms per level.
double InnerProduct(int n, int p, int m);

// C = A B with A a x b and B b x c: a b c.
double DenseProduct(double a, double b, double c);

// LU with partial pivoting of an N x N matrix: sum_k (N - k - 1)(N - k) = (N^3 - N) / 3
// (the multipliers and the rank-one updates).
double LuFactorization(double size);

// Forward and backward substitution with the LU factors, per right-hand side: N^2.
double LuSolve(double size, double right_hand_sides);

// Householder QR of a rows x cols matrix (rows >= cols), R only: per reflector k the
// norm of its column (rows - k) and, for each of the cols - k - 1 columns to its
// right, a dot product and an update (2 (rows - k)).
double HouseholderQr(double rows, double cols);

// Applying the cols reflectors of that QR to `right_hand_sides` further columns:
// 2 (rows - k) per reflector and column.
double ApplyHouseholderReflectors(double rows, double cols, double right_hand_sides);

// Singular values of an N x N matrix: the Householder bidiagonalisation,
// 4 N^3 / 3 (the iteration on the bidiagonal matrix is O(N^2)).
double SingularValues(double size);

// Back substitution with an upper-triangular N x N factor per right-hand side:
// N (N + 1) / 2.
double TriangularSolve(double size, double right_hand_sides);

}  // namespace mcrewave::operation_counts
