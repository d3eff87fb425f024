#include "mcrewave/model/simulation.h"

#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mcrewave/data/noise.h"
#include "mcrewave/linalg/band_matrix.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/model/exact_solution.h"

namespace mcrewave {
namespace {

// Simulation on `bar` with `steps_per_sample` steps of `time.step / steps_per_sample`
// between two samples of the output grid t_k = k time.step, node 0 clamped
// (support_stiffness = +inf) or held by a spring of stiffness k_s = support_stiffness
// [N/m]: K + k_s e_0 e_0^T on every node, u0 = u_0 and f0 = -k_s u_0.
ChannelSet SimulateSupported(const BarProperties& bar, const LoadOptions& load,
                             const TimeOptions& time, int steps_per_sample,
                             const std::vector<ModulusZone>& zones,
                             const std::vector<std::string>& sensors, double support_stiffness) {
  const BarModel model(bar);
  // K = sum_e E_e K1_e with the truth's element moduli (in series where a zone ends
  // inside an element); without zones, E K1 as the paper's bar.
  const SparseMatrix stiffness = zones.empty()
                                     ? model.Stiffness(bar.modulus)
                                     : model.StiffnessOfElements(ElementModuli(bar, zones));
  const bool clamped = !std::isfinite(support_stiffness);
  SparseMatrix free_mass = clamped ? BarModel::ClampedBlock(model.mass()) : model.mass();
  SparseMatrix free_stiffness = clamped ? BarModel::ClampedBlock(stiffness) : stiffness;
  if (!clamped) free_stiffness.coeffRef(0, 0) += support_stiffness;
  // The integrated dofs: nodes 1..N when clamped, else 0..N.
  const int num_free = model.num_nodes() - (clamped ? 1 : 0);
  const int loaded = num_free - 1;  // node N in the free numbering

  ThetaIntegratorOptions integrator_options;
  integrator_options.time_step = time.step / steps_per_sample;
  integrator_options.theta = time.theta;
  ThetaIntegrator integrator;
  integrator.Init(free_mass, free_stiffness, integrator_options);
  BandLdlt mass_factor;
  // The mass factor gives the clamped reaction's accelerations; a spring's force needs none.
  if (clamped && !mass_factor.Compute(SymmetricBandMatrix(free_mass))) {
    throw std::runtime_error("clamped simulation: the mass matrix is not positive definite");
  }

  // Coupling of node 0 to node 1 in row 0 of M and K (linear elements).
  const double mass_01 = model.mass().coeff(0, 1);
  const double stiffness_01 = stiffness.coeff(0, 1);

  const int num_samples = time.NumSteps() + 1;
  const int num_steps = time.NumSteps() * steps_per_sample;
  const double h = integrator_options.time_step;
  const double theta = time.theta;
  ChannelSet out =
      BarChannelSet(0.0, time.step, Vector::Zero(num_samples), Vector::Zero(num_samples),
                    Vector::Zero(num_samples), Vector::Zero(num_samples));
  // The interior sensors' rows on this mesh (clamped: u_0 = 0).
  std::vector<ObservationRow> rows;
  for (const std::string& name : sensors) {
    ChannelName channel;
    std::string why;
    const bool parsed = ParseChannelName(name, &channel, &why);
    assert(parsed && channel.kind == ChannelName::Kind::kSensor);
    (void)parsed;
    rows.push_back(channel.sensor_kind == SensorKind::kStrain
                       ? model.StrainRow(channel.position)
                       : model.DisplacementRow(channel.position));
    out.Add(name,
            channel.sensor_kind == SensorKind::kStrain ? ChannelKind::kStrain
                                                       : ChannelKind::kDisplacement,
            Vector::Zero(num_samples));
  }
  // The channels written in the time loop, looked up once (the set is complete).
  Vector& out_u0 = out.Values("u0");
  Vector& out_uL = out.Values("uL");
  Vector& out_f0 = out.Values("f0");
  Vector& out_fL = out.Values("fL");
  std::vector<Vector*> out_sensors;
  for (const BarSensor& sensor : BarSensors(out)) {
    out_sensors.push_back(&out.channels[static_cast<std::size_t>(sensor.index)].values);
  }
  Vector nodal = Vector::Zero(model.num_nodes());  // all nodes (clamped: u_0 = 0)

  Vector acceleration = Vector::Zero(num_free);
  const Vector zero = Vector::Zero(num_free);
  integrator.SweepForward(
      num_steps, zero, zero,
      [&](int k, Eigen::Ref<Vector> force) {
        // f_theta = theta F(t_{k+1}) + (1 - theta) F(t_k) on the loaded node.
        force.setZero();
        force[loaded] = theta * load.Value((k + 1) * h) + (1.0 - theta) * load.Value(k * h);
      },
      [&](int k, const Vector& /*velocity*/, const Vector& displacement) {
        if (k % steps_per_sample != 0) return;
        const int sample = k / steps_per_sample;
        const double applied = load.Value(k * h);
        // Clamped: M_r a_k = f_k - K_r u_k, then f0_k = M_01 a_1 + K_01 u_1.
        if (clamped) {
          integrator.stiffness().Multiply(displacement, acceleration);
          acceleration = -acceleration;
          acceleration[loaded] += applied;
          mass_factor.SolveInPlace(acceleration);
        }
        out_uL[sample] = displacement[loaded];
        if (!rows.empty()) {
          nodal.tail(num_free) = displacement;
          for (std::size_t r = 0; r < rows.size(); ++r) {
            (*out_sensors[r])[sample] = rows[r].Apply(nodal.data());
          }
        }
        if (clamped) {
          out_f0[sample] = mass_01 * acceleration[0] + stiffness_01 * displacement[0];
        } else {
          // The spring's force on the bar, f0 = -k_s u_0.
          out_u0[sample] = displacement[0];
          out_f0[sample] = -support_stiffness * displacement[0];
        }
        out_fL[sample] = applied;
      });
  return out;
}

}  // namespace

ChannelSet SimulateClampedBar(const BarProperties& bar, const LoadOptions& load,
                              const TimeOptions& time, const std::vector<ModulusZone>& zones,
                              const std::vector<std::string>& sensors) {
  return SimulateSupported(bar, load, time, 1, zones, sensors,
                           std::numeric_limits<double>::infinity());
}

ChannelSet SimulateTruth(const BarProperties& bar, const LoadOptions& load, const TimeOptions& time,
                         const DataOptions& data) {
  if (data.truth == TruthModel::kExact) {
    assert(data.truth_zones.empty() && data.sensors.empty());
    return ExactBarSolution(bar, load).Sample(time);
  }
  BarProperties fine = bar;
  fine.elements = bar.elements * data.truth_refinement;
  return SimulateSupported(fine, load, time, data.truth_refinement, data.truth_zones, data.sensors,
                           data.support_stiffness);
}

ChannelSet MakeSyntheticMeasurements(const BarProperties& bar, const LoadOptions& load,
                                     const TimeOptions& time, const DataOptions& data) {
  ChannelSet measurements = SimulateTruth(bar, load, time, data);
  AddMeasurementNoise(data.snr, data.seed, &measurements);
  return measurements;
}

}  // namespace mcrewave
