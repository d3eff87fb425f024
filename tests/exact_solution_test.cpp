// Independent checks of the exact solution of the clamped bar (exact_solution.h),
// which is computed by d'Alembert's sum of reflected pulses: a modal series written
// here with closed-form Duhamel integrals, boundary conditions, the momentum
// balance of the whole bar, the quasi-static limit and the wave arrival time.
#include "mcrewave/model/exact_solution.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace mcrewave {
namespace {

double WaveSpeed(const BarProperties& bar) { return std::sqrt(bar.modulus / bar.density); }

std::string Scientific(double value) {
  std::ostringstream text;
  text << std::scientific << value;
  return text.str();
}

// sin(z) / z, with its limit 1 at z = 0.
double Sinc(double z) { return std::abs(z) < 1e-8 ? 1.0 - z * z / 6.0 : std::sin(z) / z; }

// The modal superposition with the quasi-static (mode acceleration) correction:
//   u(x, t) = F(t) x / (E S) + sum_{n=1}^{N} (q_n(t) - F(t) phi_n(L) / (m_n omega_n^2)) phi_n(x),
// phi_n = sin(k_n x), k_n = (2n - 1) pi / (2 L), omega_n = c k_n, m_n = rho S L / 2,
//   q_n'' + omega_n^2 q_n = F(t) phi_n(L) / m_n,  q_n(0) = q_n'(0) = 0.
// F x / (E S) = sum_n F phi_n(L) phi_n(x) / (m_n omega_n^2) is the static response, so the
// series only carries the dynamic remainder, whose terms decay like n^-3 (displacement) and
// n^-2 (strain) instead of n^-2 and n^-1.
class ModalSeries {
 public:
  ModalSeries(const BarProperties& bar, const LoadOptions& load, int num_modes)
      : bar_(bar), load_(load), num_modes_(num_modes) {}

  double Displacement(double x, double time) const { return Sum(x, time, false); }
  // f0 = -E S u_x(0, t).
  double ClampForce(double time) const {
    return -bar_.modulus * bar_.section * Sum(0.0, time, true);
  }

 private:
  // Duhamel: q_n(t) = F0 phi_n(L) / (m_n omega_n) J(t), with a = pi / t_load,
  // tau = min(t, t_load), delta = a - omega_n and
  //   J = int_0^tau sin(a s) sin(omega_n (t - s)) ds
  //     = 1/2 [(sin((a + omega_n) tau - omega_n t) + sin(omega_n t)) / (a + omega_n)
  //            - (sin(omega_n t + delta tau) - sin(omega_n t)) / delta],
  // the last quotient written tau cos(omega_n t + delta tau / 2) sinc(delta tau / 2), which
  // is exact and stable at and near resonance (delta -> 0).
  double DuhamelIntegral(double omega, double time) const {
    const double a = M_PI / load_.duration;
    const double tau = std::min(time, load_.duration);
    const double delta = a - omega;
    const double first =
        (std::sin((a + omega) * tau - omega * time) + std::sin(omega * time)) / (a + omega);
    const double second =
        tau * std::cos(omega * time + 0.5 * delta * tau) * Sinc(0.5 * delta * tau);
    return 0.5 * (first - second);
  }

  // u(x, t), or u_x(x, t) when derivative is true.
  double Sum(double x, double time, bool derivative) const {
    const double length = bar_.length;
    const double c = WaveSpeed(bar_);
    const double modal_mass = 0.5 * bar_.density * bar_.section * length;
    const double force = load_.Value(time);
    const double stiffness = bar_.modulus * bar_.section;
    // Static part F x / (E S) or its derivative F / (E S).
    double sum = derivative ? force / stiffness : force * x / stiffness;
    for (int n = num_modes_; n >= 1; --n) {  // smallest terms first
      const double k = (2 * n - 1) * M_PI / (2.0 * length);
      const double omega = c * k;
      // phi_n(L) = sin((2n - 1) pi / 2) = (-1)^(n + 1).
      const double phi_end = n % 2 == 1 ? 1.0 : -1.0;
      const double dynamic =
          load_.amplitude * phi_end / (modal_mass * omega) * DuhamelIntegral(omega, time);
      const double quasi_static = force * phi_end / (modal_mass * omega * omega);
      const double shape = derivative ? k * std::cos(k * x) : std::sin(k * x);
      sum += (dynamic - quasi_static) * shape;
    }
    return sum;
  }

  BarProperties bar_;
  LoadOptions load_;
  int num_modes_;
};

// Composite Simpson rule of f on [a, b] with an even number of intervals.
template <typename Function>
double Simpson(Function&& f, double a, double b, int intervals) {
  const double dx = (b - a) / intervals;
  double sum = f(a) + f(b);
  for (int i = 1; i < intervals; ++i) sum += (i % 2 == 1 ? 4.0 : 2.0) * f(a + i * dx);
  return sum * dx / 3.0;
}

TEST(ExactBarSolutionTest, AgreesWithTheModalSeries) {
  const BarProperties bar;
  const LoadOptions load;
  const ExactBarSolution exact(bar, load);
  const ModalSeries modal(bar, load, 20000);
  const double static_displacement = load.amplitude * bar.length / (bar.modulus * bar.section);
  double max_u_error = 0.0, max_f_error = 0.0, max_u = 0.0, max_f = 0.0;
  const TimeOptions time;
  // 97 samples over the window, not aligned with the wave fronts.
  for (int i = 0; i <= 97; ++i) {
    const double t = i * time.window / 97;
    max_u = std::max(max_u, std::abs(exact.Displacement(bar.length, t)));
    max_f = std::max(max_f, std::abs(exact.ClampForce(t)));
    max_u_error = std::max(max_u_error, std::abs(exact.Displacement(bar.length, t) -
                                                 modal.Displacement(bar.length, t)));
    max_f_error = std::max(max_f_error, std::abs(exact.ClampForce(t) - modal.ClampForce(t)));
  }
  RecordProperty("uL_modal_difference", Scientific(max_u_error / max_u));
  RecordProperty("f0_modal_difference", Scientific(max_f_error / max_f));
  // The response is not trivially small: the end moves by more than the static deflection
  // and the clamp sees the doubled pulse.
  EXPECT_GT(max_u, static_displacement);
  EXPECT_NEAR(max_f, 2.0 * load.amplitude, 1e-3 * load.amplitude);
  EXPECT_LT(max_u_error, 1e-10 * max_u);
  EXPECT_LT(max_f_error, 1e-7 * max_f);
}

TEST(ExactBarSolutionTest, AgreesWithTheModalSeriesInsideTheBarAndAtResonance) {
  const BarProperties bar;
  LoadOptions load;
  // pi / t_load = omega_1 = pi c / (2 L): the first mode is driven at resonance.
  load.duration = 2.0 * bar.length / WaveSpeed(bar);
  const ExactBarSolution exact(bar, load);
  const ModalSeries modal(bar, load, 20000);
  const double scale = std::abs(exact.Displacement(bar.length, load.duration));
  for (double x : {0.1, 0.37, 0.5, 0.81}) {
    for (double t : {0.3e-4, 1.1e-4, 2.3e-4, 4.9e-4}) {
      EXPECT_NEAR(exact.Displacement(x, t), modal.Displacement(x, t), 1e-11 * scale)
          << "x = " << x << ", t = " << t;
    }
  }
}

TEST(ExactBarSolutionTest, SatisfiesTheBoundaryConditions) {
  const BarProperties bar;
  const LoadOptions load;
  const ExactBarSolution exact(bar, load);
  const double stiffness = bar.modulus * bar.section;
  const double dx = 1e-4 * bar.length;
  for (double t : {0.2e-4, 0.5e-4, 0.8e-4, 2.0e-4, 4.5e-4}) {
    EXPECT_EQ(exact.Displacement(0.0, t), 0.0);
    // E S u_x(L, t) = F(t), u_x by the second-order one-sided difference
    // (3 u(L) - 4 u(L - dx) + u(L - 2 dx)) / (2 dx).
    const double strain =
        (3.0 * exact.Displacement(bar.length, t) - 4.0 * exact.Displacement(bar.length - dx, t) +
         exact.Displacement(bar.length - 2.0 * dx, t)) /
        (2.0 * dx);
    EXPECT_NEAR(stiffness * strain, load.Value(t), 1e-7 * load.amplitude) << "t = " << t;
  }
}

TEST(ExactBarSolutionTest, MomentumOfTheBarEqualsTheImpulseOfTheEndForces) {
  // d/dt int_0^L rho S u_t dx = F(t) + f0(t): the momentum at t (u_t by central
  // differences, Simpson in x) equals int_0^t (F + f0) ds (Simpson in time).
  const BarProperties bar;
  const LoadOptions load;
  const ExactBarSolution exact(bar, load);
  const double dt = 1e-9;
  const double total_impulse = 2.0 * load.amplitude * load.duration / M_PI;
  for (double t : {0.9e-4, 2.7e-4, 4.4e-4, 6.3e-4}) {
    const double momentum = Simpson(
        [&](double x) {
          const double velocity =
              (exact.Displacement(x, t + dt) - exact.Displacement(x, t - dt)) / (2.0 * dt);
          return bar.density * bar.section * velocity;
        },
        0.0, bar.length, 4000);
    const double impulse =
        Simpson([&](double s) { return load.Value(s) + exact.ClampForce(s); }, 0.0, t, 20000);
    EXPECT_NEAR(momentum, impulse, 2e-7 * total_impulse) << "t = " << t;
  }
}

TEST(ExactBarSolutionTest, SlowLoadGivesTheStaticResponse) {
  // A load 2000 times longer than the transit time L / c: near its peak the bar is in
  // static equilibrium under the current load, uL = F(t) L / (E S), u(L / 4) = uL / 4 and
  // f0 = -F(t), up to the free vibration started by the load's initial slope
  // s = F0 pi / t_load. For a ramp F = s t, f0 + F is a triangle wave of amplitude s L / c
  // and uL - F L / (E S) one of amplitude s L^2 / (2 c E S) (the end velocity deviation is
  // a square wave of height s L / (c Z), Z = rho c S). The times sweep one period 4 L / c
  // of the first mode.
  const BarProperties bar;
  LoadOptions load;
  const double c = WaveSpeed(bar);
  const double transit = bar.length / c;
  load.duration = 2000.0 * transit;
  const ExactBarSolution exact(bar, load);
  const double stiffness = bar.modulus * bar.section;
  const double slope = load.amplitude * M_PI / load.duration;
  const double f0_amplitude = slope * bar.length / c;
  const double uL_amplitude = slope * bar.length * bar.length / (2.0 * c * stiffness);
  double max_f0_deviation = 0.0, max_uL_deviation = 0.0;
  for (int j = 0; j < 16; ++j) {
    const double t = 0.5 * load.duration + 0.25 * j * transit;
    const double force = load.Value(t);
    const double static_end_displacement = force * bar.length / stiffness;
    max_f0_deviation = std::max(max_f0_deviation, std::abs(exact.ClampForce(t) + force));
    max_uL_deviation = std::max(
        max_uL_deviation, std::abs(exact.Displacement(bar.length, t) - static_end_displacement));
    EXPECT_NEAR(exact.Displacement(0.25 * bar.length, t), 0.25 * static_end_displacement,
                uL_amplitude)
        << "t = " << t;
  }
  // The deviations are 1e-3 of the static values; their amplitudes match the ramp's.
  EXPECT_NEAR(max_f0_deviation, f0_amplitude, 0.01 * f0_amplitude);
  EXPECT_NEAR(max_uL_deviation, uL_amplitude, 0.01 * uL_amplitude);
  EXPECT_LT(f0_amplitude, 2e-3 * load.amplitude);
}

TEST(ExactBarSolutionTest, NothingHappensBeforeTheWaveArrives) {
  const BarProperties bar;
  const LoadOptions load;
  const ExactBarSolution exact(bar, load);
  const double transit = bar.length / WaveSpeed(bar);
  for (int i = 0; i < 100; ++i) {
    const double t = 0.999 * transit * i / 99.0;
    EXPECT_EQ(exact.ClampForce(t), 0.0) << "t = " << t;
  }
  // At mid-length the displacement starts at L / (2 c).
  EXPECT_EQ(exact.Displacement(0.5 * bar.length, 0.499 * transit), 0.0);
  EXPECT_GT(exact.Displacement(0.5 * bar.length, 0.501 * transit), 0.0);
  // Just after the arrival the clamp pulls the bar back (tension wave): f0 < 0.
  EXPECT_LT(exact.ClampForce(1.001 * transit), 0.0);
}

TEST(ExactBarSolutionTest, SampleHoldsTheFourChannels) {
  const BarProperties bar;
  const LoadOptions load;
  TimeOptions time;
  time.window = 1e-4;
  time.step = 1e-6;
  const ExactBarSolution exact(bar, load);
  const ChannelSet samples = exact.Sample(time);
  ASSERT_EQ(samples.num_samples(), 101);
  EXPECT_EQ(samples.start_time, 0.0);
  EXPECT_EQ(samples.time_step, time.step);
  for (int k = 0; k <= 100; ++k) {
    const double t = k * time.step;
    EXPECT_EQ(samples.Values("u0")[k], 0.0);
    EXPECT_EQ(samples.Values("uL")[k], exact.Displacement(bar.length, t));
    EXPECT_EQ(samples.Values("f0")[k], exact.ClampForce(t));
    EXPECT_EQ(samples.Values("fL")[k], load.Value(t));
  }
}

}  // namespace
}  // namespace mcrewave
