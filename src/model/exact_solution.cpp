// The exact solution of the clamped bar under the half-sine end load.
//
// Method: d'Alembert (method of characteristics), i.e. the sum of the pulses
// reflected at the two ends. It is exact for this 1-D wave problem and needs only
// a finite number of terms at any time, so there is no truncation error (a modal
// series would need ~1e5 modes with a quasi-static correction to reach 1e-10 on
// uL, and converges only like 1/n on the clamp force). The modal superposition
// is the Fourier expansion of the same function; tests/exact_solution_test.cpp
// evaluates it independently (closed-form Duhamel integrals, resonant case
// included) and checks that both agree.
//
// Derivation. rho S u_tt = E S u_xx on (0, L), u(0, t) = 0, E S u_x(L, t) = F(t),
// u = u_t = 0 at t = 0. With c = sqrt(E / rho), the impedance Z = rho c S and the
// impulse I(t) = int_0^t F(s) ds, the load sends the left-going wave
// G(t - (L - x) / c) with G = I / Z (then E S u_x(L, t) = E S G'(t) / c = F(t)).
// A fixed end reflects displacement with a change of sign, a free end without,
// so the j-th round trip contributes
//   u(x, t) = sum_{j >= 0} (-1)^j [G(t - ((2j + 1) L - x) / c) - G(t - ((2j + 1) L + x) / c)],
// with G(s) = 0 for s < 0 (finitely many non-zero terms). At x = 0 the two waves
// of each j cancel (u = 0); at x = L the right-going wave of j and the left-going
// wave of j + 1 have opposite strains, so only the applied one remains. Hence
//   u(L, t) = G(t) + 2 sum_{j >= 1} (-1)^j G(t - 2 j L / c),
//   f0(t) = -E S u_x(0, t) = -2 sum_{j >= 0} (-1)^j F(t - (2j + 1) L / c).
// For the half sine F = F0 sin(pi t / t_load) on [0, t_load]:
//   I(t) = F0 t_load / pi (1 - cos(pi t / t_load)) on [0, t_load], 2 F0 t_load / pi after.
#include "mcrewave/model/exact_solution.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

namespace mcrewave {
namespace {

// I(t) = int_0^t F(s) ds [N s] of the half-sine load.
double LoadImpulse(const LoadOptions& load, double time) {
  if (time <= 0.0) return 0.0;
  const double clipped = std::min(time, load.duration);
  // I(t) = F0 t_load / pi (1 - cos(pi min(t, t_load) / t_load)).
  return load.amplitude * load.duration / M_PI * (1.0 - std::cos(M_PI * clipped / load.duration));
}

}  // namespace

ExactBarSolution::ExactBarSolution(const BarProperties& bar, const LoadOptions& load)
    : bar_(bar), load_(load) {
  assert(load.kind == LoadKind::kHalfSine);
}

double ExactBarSolution::Displacement(double x, double time) const {
  assert(x >= 0.0 && x <= bar_.length);
  const double wave_speed = std::sqrt(bar_.modulus / bar_.density);
  const double impedance = bar_.density * wave_speed * bar_.section;
  const double length = bar_.length;
  double displacement = 0.0;
  double sign = 1.0;
  // A round trip whose left-going wave has not reached x yet contributes nothing, nor do
  // the later ones.
  for (int j = 0;; ++j, sign = -sign) {
    // Arrival times at x of the left-going and right-going waves of round trip j.
    const double left_going = time - ((2 * j + 1) * length - x) / wave_speed;
    const double right_going = time - ((2 * j + 1) * length + x) / wave_speed;
    if (left_going <= 0.0) break;
    // u += (-1)^j [I(left_going) - I(right_going)] / Z.
    displacement +=
        sign * (LoadImpulse(load_, left_going) - LoadImpulse(load_, right_going)) / impedance;
  }
  return displacement;
}

double ExactBarSolution::ClampForce(double time) const {
  const double travel_time = bar_.length / std::sqrt(bar_.modulus / bar_.density);
  double force = 0.0;
  double sign = 1.0;
  // Same stopping rule: the pulse of round trip j reaches x = 0 at (2j + 1) L / c.
  for (int j = 0;; ++j, sign = -sign) {
    const double arrival = time - (2 * j + 1) * travel_time;
    if (arrival <= 0.0) break;
    // f0 -= 2 (-1)^j F(t - (2j + 1) L / c).
    force -= 2.0 * sign * load_.Value(arrival);
  }
  return force;
}

ChannelSet ExactBarSolution::Sample(const TimeOptions& time) const {
  const int num_samples = time.NumSteps() + 1;
  Vector uL(num_samples), f0(num_samples), fL(num_samples);
  for (int k = 0; k < num_samples; ++k) {
    const double t = k * time.step;
    uL[k] = Displacement(bar_.length, t);
    f0[k] = ClampForce(t);
    fL[k] = load_.Value(t);
  }
  return BarChannelSet(0.0, time.step, Vector::Zero(num_samples), std::move(uL), std::move(f0),
                       std::move(fL));
}

}  // namespace mcrewave
