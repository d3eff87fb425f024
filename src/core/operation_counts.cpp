#include "mcrewave/core/operation_counts.h"

namespace mcrewave::operation_counts {

double BandProduct(int n, int p) {
  // n diagonal entries and 2 (n - d) off-diagonal entries per diagonal d = 1..p.
  return static_cast<double>(n) * (2.0 * p + 1.0) - static_cast<double>(p) * (p + 1.0);
}

double BandSolve(int n, int p) {
  // Entries of L strictly below the diagonal: sum_{d=1..p} (n - d).
  const double strictly_lower = static_cast<double>(n) * p - 0.5 * p * (p + 1.0);
  return 2.0 * strictly_lower + n;
}

double BandProductAdd(int n, int p) { return BandProduct(n, p) + n; }

double ThetaStep(int n, int p, bool with_force) {
  // rhs = R v - h K u: a band product and a scaled one; h f: n; solve;
  // u' = u + a v + b v': 2n.
  return BandProduct(n, p) + BandProductAdd(n, p) + (with_force ? n : 0.0) + BandSolve(n, p) +
         2.0 * n;
}

double DirectSweep(int n, int p, int m) {
  // Per level: K W_j and the 2 end entries of W_j / alpha; per step:
  // f_theta = theta g_{k+1} + (1 - theta) g_k and the step.
  const double per_level = BandProduct(n, p) + 2.0;
  return (m + 1.0) * per_level + m * (2.0 * n + ThetaStep(n, p, true));
}

double RetrogradeSweep(int n, int p, int m) {
  // Per step: c_j beta (B U_j - U~_j) at the 2 end nodes and the step; per level:
  // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j.
  return m * (2.0 + ThetaStep(n, p, true)) + (m + 1.0) * 3.0 * n;
}

double InnerProduct(int n, int p, int m) {
  // Per level: K y_j, x_j . (K y_j), the 2 end terms / alpha and the weight c_j h.
  return (m + 1.0) * (BandProduct(n, p) + n + 4.0);
}

double DenseProduct(double a, double b, double c) { return a * b * c; }

double LuFactorization(double size) { return (size * size * size - size) / 3.0; }

double LuSolve(double size, double right_hand_sides) { return size * size * right_hand_sides; }

double HouseholderQr(double rows, double cols) {
  double macs = 0.0;
  for (double k = 0; k < cols; ++k) {
    macs += (rows - k) + (cols - k - 1.0) * 2.0 * (rows - k);
  }
  return macs;
}

double ApplyHouseholderReflectors(double rows, double cols, double right_hand_sides) {
  double macs = 0.0;
  for (double k = 0; k < cols; ++k) macs += 2.0 * (rows - k);
  return macs * right_hand_sides;
}

double SingularValues(double size) { return 4.0 * size * size * size / 3.0; }

double TriangularSolve(double size, double right_hand_sides) {
  return 0.5 * size * (size + 1.0) * right_hand_sides;
}

}  // namespace mcrewave::operation_counts
