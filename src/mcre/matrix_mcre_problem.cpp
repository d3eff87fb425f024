#include "mcrewave/mcre/matrix_mcre_problem.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mcrewave/mcre/element_error_map.h"

namespace mcrewave {

ChannelSet MatrixChannelSet(const MatrixModelData& model, double time_step, const Matrix& loads,
                            const Matrix& outputs) {
  assert(loads.rows() == static_cast<Eigen::Index>(model.loads.size()) &&
         outputs.rows() == static_cast<Eigen::Index>(model.sensors.size()) &&
         outputs.cols() == loads.cols());
  ChannelSet set;
  set.time_step = time_step;
  for (std::size_t c = 0; c < model.loads.size(); ++c) {
    set.Add(model.loads[c].channel, ChannelKind::kForce,
            loads.row(static_cast<Eigen::Index>(c)).transpose());
  }
  for (std::size_t k = 0; k < model.sensors.size(); ++k) {
    set.Add(model.sensors[k].channel,
            model.sensors[k].kind == SensorKind::kStrain ? ChannelKind::kStrain
                                                         : ChannelKind::kDisplacement,
            outputs.row(static_cast<Eigen::Index>(k)).transpose());
  }
  return set;
}

SparseMatrix WithHeldDofs(SparseMatrix matrix, const std::vector<char>& held) {
  for (int column = 0; column < matrix.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(matrix, column); entry; ++entry) {
      if (entry.row() != entry.col() && (held[entry.row()] != 0 || held[entry.col()] != 0)) {
        entry.valueRef() = 0.0;
      }
    }
  }
  matrix.prune(0.0);
  return matrix;
}

namespace {

// One load channel or one row of H as the constructor gathers them: the spatial vector
// or row, its weight and the data's channel ("" for the datum 0).
struct LoadColumn {
  const Vector* vector;
  double alpha;
  std::string channel;
  // An unmeasured load's: its datum is 0 (the data's channel not read) and it acts over
  // [start, end] [s] only.
  bool measured = true;
  double start = -std::numeric_limits<double>::infinity();
  double end = std::numeric_limits<double>::infinity();
};
struct ObservedRow {
  SparseRow row;  // 1 x n
  double beta;
  std::string channel;
  ChannelKind kind;
};

// The sparse 1 x n row of a dense vector's nonzero entries.
SparseRow RowOf(const Vector& vector) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < vector.size(); ++i) {
    if (vector[i] != 0.0) entries.emplace_back(0, i, vector[i]);
  }
  SparseRow row(1, vector.size());
  row.setFromTriplets(entries.begin(), entries.end());
  return row;
}

// The dofs of the model's supports, flagged 1 in an n-vector (trusted: held).
std::vector<char> HeldDofs(const MatrixModelData& model) {
  std::vector<char> held(static_cast<std::size_t>(model.dofs()), 0);
  for (const MatrixModelSupport& support : model.supports) {
    for (const int dof : support.dofs) held[static_cast<std::size_t>(dof)] = 1;
  }
  return held;
}

// G: the model's loads (unmeasured ones: alpha_u), then the supports' forces (measured:
// alpha; pinned: alpha_0).
std::vector<LoadColumn> LoadColumns(const MatrixModelData& model, double force_alpha,
                                    double unmeasured_alpha, double reaction_weight, bool measured,
                                    bool pinned, const std::vector<UnmeasuredLoad>& unmeasured) {
  std::vector<LoadColumn> columns;
  for (const MatrixModelLoad& load : model.loads) {
    columns.push_back({&load.vector, force_alpha, load.channel});
    for (const UnmeasuredLoad& free_load : unmeasured) {
      if (free_load.channel != load.channel) continue;
      columns.back().alpha = unmeasured_alpha;
      columns.back().measured = false;
      columns.back().start = free_load.start;
      columns.back().end = free_load.end;
    }
  }
  for (const UnmeasuredLoad& free_load : unmeasured) {
    const bool found = std::any_of(model.loads.begin(), model.loads.end(), [&](const auto& load) {
      return load.channel == free_load.channel;
    });
    if (!found) {
      throw std::logic_error("the unmeasured load '" + free_load.channel +
                             "' is no load channel of the model");
    }
  }
  if (measured || pinned) {
    for (const MatrixModelSupport& support : model.supports) {
      columns.push_back(
          {&support.reaction, measured ? force_alpha : reaction_weight, support.force_channel});
    }
  }
  return columns;
}

// H: the model's sensors, then the supports' displacement rows g^T / (g^T g)
// (measured, with a displacement channel) or the data 0 of e_i^T (pinned).
std::vector<ObservedRow> ObservedRows(const MatrixModelData& model, const McreWeights& weights,
                                      double stiffness_scale, bool measured, bool pinned) {
  const int n = model.dofs();
  std::vector<ObservedRow> rows;
  for (const MatrixModelSensor& sensor : model.sensors) {
    const bool strain = sensor.kind == SensorKind::kStrain;
    rows.push_back({sensor.row,
                    strain ? weights.strain_weight * stiffness_scale * model.length * model.length
                           : weights.displacement_weight * stiffness_scale,
                    sensor.channel, strain ? ChannelKind::kStrain : ChannelKind::kDisplacement});
  }
  for (const MatrixModelSupport& support : model.supports) {
    if (measured && !support.displacement_channel.empty()) {
      rows.push_back({RowOf(support.reaction / support.reaction.squaredNorm()),
                      weights.displacement_weight * stiffness_scale, support.displacement_channel,
                      ChannelKind::kDisplacement});
    }
    if (pinned) {
      for (const int dof : support.dofs) {
        rows.push_back({RowOf(Vector::Unit(n, dof)),
                        weights.clamp_displacement_weight * stiffness_scale, "",
                        ChannelKind::kDisplacement});
      }
    }
  }
  return rows;
}

// G's channels gathered once into rows (columns t_j for the sweeps): F~ into
// measured_loads (an unmeasured load's 0), alpha_c into alphas, a_cj into active (left
// empty when every load acts at every sample), and G (n x C), a load on a held dof
// dropped.
void GatherLoads(const std::vector<LoadColumn>& columns, const ChannelSet& data,
                 const std::vector<char>& held, int n, Matrix* measured_loads, Vector* alphas,
                 Matrix* active, SparseMatrix* loads) {
  const int num_loads = static_cast<int>(columns.size());
  const int samples = data.num_samples();
  measured_loads->resize(num_loads, samples);
  alphas->resize(num_loads);
  Matrix acts = Matrix::Ones(num_loads, samples);
  bool intervals = false;
  std::vector<Eigen::Triplet<double>> entries;
  for (int c = 0; c < num_loads; ++c) {
    if (columns[c].measured) {
      measured_loads->row(c) = data.Values(columns[c].channel).transpose();
    } else {
      measured_loads->row(c).setZero();
      // a_cj = 1 on t_j in [start, end], to a millionth of a step.
      const double slack = 1e-6 * data.time_step;
      for (int j = 0; j < samples; ++j) {
        const double time = j * data.time_step;
        if (time < columns[c].start - slack || time > columns[c].end + slack) {
          acts(c, j) = 0.0;
          intervals = true;
        }
      }
    }
    (*alphas)[c] = columns[c].alpha;
    const Vector& g = *columns[c].vector;
    for (int i = 0; i < n; ++i) {
      // A load on a held dof goes into the support.
      if (g[i] != 0.0 && (held.empty() || held[i] == 0)) entries.emplace_back(i, c, g[i]);
    }
  }
  loads->resize(n, num_loads);
  loads->setFromTriplets(entries.begin(), entries.end());
  if (intervals) {
    *active = std::move(acts);
  } else {
    active->resize(0, 0);
  }
}

// H's fixed rows gathered once: d~ into the first rows of measured_outputs (0 for the
// datum 0), beta_k into betas, and the rows (num_fixed x n), held columns dropped.
void GatherFixedRows(const std::vector<ObservedRow>& rows, const ChannelSet& data,
                     const std::vector<char>& held, int n, Matrix* measured_outputs, Vector* betas,
                     SparseMatrix* fixed_observation) {
  const int num_fixed = static_cast<int>(rows.size());
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < num_fixed; ++k) {
    if (rows[k].channel.empty()) {
      measured_outputs->row(k).setZero();
    } else {
      measured_outputs->row(k) = data.Values(rows[k].channel).transpose();
    }
    (*betas)[k] = rows[k].beta;
    for (int outer = 0; outer < rows[k].row.outerSize(); ++outer) {
      for (SparseRow::InnerIterator it(rows[k].row, outer); it; ++it) {
        // U = 0 on a held dof: the row's entry there observes nothing and would load it.
        if (!held.empty() && held[it.col()] != 0) continue;
        entries.emplace_back(k, static_cast<int>(it.col()), it.value());
      }
    }
  }
  fixed_observation->resize(num_fixed, n);
  fixed_observation->setFromTriplets(entries.begin(), entries.end());
}

// The reactions r_s(U) = phi_s^T K(E) U = sum_z E_z (phi_s^T K_z / E_z,nom) U: per zone
// the rows phi_s^T K_z / E_z,nom, held columns dropped (U = 0 there); phi_s the support's
// TrustedReactionTest, g_s unless it extends over free dofs (docs/boundaries.md section 7).
std::vector<SparseMatrix> ReactionZoneRows(const MatrixModelData& model,
                                           const std::vector<char>& held) {
  const int n = model.dofs();
  const int num_reactions = static_cast<int>(model.supports.size());
  std::vector<SparseMatrix> zone_rows_by_zone;
  std::vector<Eigen::Triplet<double>> entries;
  for (const MatrixModelZone& zone : model.zones) {
    entries.clear();
    for (int s = 0; s < num_reactions; ++s) {
      const Vector row = (zone.stiffness.transpose() * TrustedReactionTest(model.supports[s])) *
                         (1.0 / zone.nominal_modulus);
      for (int i = 0; i < n; ++i) {
        if (row[i] != 0.0 && held[i] == 0) entries.emplace_back(s, i, row[i]);
      }
    }
    SparseMatrix zone_rows(num_reactions, n);
    zone_rows.setFromTriplets(entries.begin(), entries.end());
    zone_rows_by_zone.push_back(std::move(zone_rows));
  }
  return zone_rows_by_zone;
}

}  // namespace

MatrixMcreProblem::MatrixMcreProblem(const MatrixModelData& model, const ChannelSet& data,
                                     const McreWeights& weights, double reference_modulus,
                                     double theta, Factorization factorization, ClampModel supports,
                                     const std::vector<UnmeasuredLoad>& unmeasured)
    : model_(model),
      time_step_(data.time_step),
      theta_(theta),
      factorization_(factorization),
      treatment_(supports) {
  const int n = model.dofs();
  assert(weights.IsValid(nullptr) && reference_modulus > 0.0 && data.num_steps() >= 1 &&
         model.stiffness_length > 0.0 && model.length > 0.0);
  // k* = E0 a*; alpha_c = w_f / k*, beta_k = w_u k* or w_e k* l*^2
  // (docs/matrix_models.md section 3); a support's alpha_r = alpha_0 = w_r / k* and
  // beta_0 = w_u0 k* (section 11).
  const double stiffness_scale = reference_modulus * model.stiffness_length;
  const double force_alpha = weights.force_weight / stiffness_scale;
  // An unmeasured load's alpha_u = w_fu / k* (docs/unmeasured_loads.md).
  const double unmeasured_alpha = weights.unmeasured_force_weight / stiffness_scale;
  reaction_weight_ = weights.reaction_weight / stiffness_scale;
  const bool has_supports = !model.supports.empty();
  const bool trusted = has_supports && supports == ClampModel::kTrusted;
  const bool pinned = has_supports && supports == ClampModel::kPinned;
  const bool measured = has_supports && supports == ClampModel::kMeasured;
  if (trusted) held_ = HeldDofs(model);
  const std::vector<LoadColumn> columns = LoadColumns(
      model, force_alpha, unmeasured_alpha, reaction_weight_, measured, pinned, unmeasured);
  const std::vector<ObservedRow> rows =
      ObservedRows(model, weights, stiffness_scale, measured, pinned);
  if (trusted) num_reactions_ = static_cast<int>(model.supports.size());
  const int num_loads = static_cast<int>(columns.size());
  const int num_fixed = static_cast<int>(rows.size());
  const int num_rows = num_fixed + num_reactions_;
  for (const LoadColumn& column : columns) load_channels_.push_back(column.channel);
  for (const ObservedRow& row : rows) {
    output_channels_.push_back(row.channel);
    output_kinds_.push_back(row.kind);
  }
  if (trusted) {
    for (const MatrixModelSupport& support : model.supports) {
      output_channels_.push_back(support.force_channel);
      output_kinds_.push_back(ChannelKind::kForce);
    }
  }
  GatherLoads(columns, data, held_, n, &measured_loads_, &alphas_, &load_active_, &loads_);
  loads_transposed_ = loads_.transpose();
  load_columns_ = SparseColumns(loads_);
  measured_outputs_.resize(num_rows, data.num_samples());
  betas_.resize(num_rows);
  GatherFixedRows(rows, data, held_, n, &measured_outputs_, &betas_, &fixed_observation_);
  if (trusted) {
    // The reactions' rows per zone, against the force channels with alpha_r.
    reaction_zone_rows_ = ReactionZoneRows(model, held_);
    for (const SparseMatrix& rows : reaction_zone_rows_) reaction_zone_forms_.emplace_back(rows);
    for (int s = 0; s < num_reactions_; ++s) {
      const Vector& test = TrustedReactionTest(model.supports[s]);
      for (std::size_t el = 0; el < model.elements.size(); ++el) {
        for (const int dof : model.elements[el].dofs) {
          if (test[dof] != 0.0) {
            reaction_elements_.emplace_back(s, static_cast<int>(el));
            break;
          }
        }
      }
    }
    for (int s = 0; s < num_reactions_; ++s) {
      measured_outputs_.row(num_fixed + s) =
          data.Values(model.supports[s].force_channel).transpose();
      betas_[num_fixed + s] = reaction_weight_;
    }
  } else {
    observation_ = fixed_observation_;
    observation_transposed_ = observation_.transpose();
    observation_columns_ = SparseColumns(observation_transposed_);
  }
  for (const MatrixModelZone& zone : model.zones) zone_forms_.emplace_back(zone.stiffness);
  mass_ = trusted ? WithHeldDofs(model.mass, held_) : model.mass;
  for (int b = 0; b < 2; ++b) {
    velocity_[b] = Vector::Zero(n);
    state_[b] = Vector::Zero(n);
  }
  shift_ = Vector::Zero(n);
  product_ = Vector::Zero(n);
  channel_ = Vector::Zero(num_loads);
  other_channel_ = Vector::Zero(num_loads);
  for (Vector& edge : edge_channel_) edge = Vector::Zero(num_loads);
  trace_ = Vector::Zero(num_rows);
  reaction_trace_ = Vector::Zero(num_reactions_);
  for (int b = 0; b < 2; ++b) {
    stream_velocity_[b] = Vector::Zero(n);
    stream_displacement_[b] = Vector::Zero(n);
    stream_retrograde_[b] = Vector::Zero(n);
  }
  if (!model.elements.empty())
    stream_density_row_ = Vector::Zero(ElementColumnPositions(model).size());
  batch_velocity_ = Matrix::Zero(n, 2 * kMaxSweepBatch);
  batch_state_ = Matrix::Zero(n, 2 * kMaxSweepBatch);
  batch_shift_ = Matrix::Zero(n, kMaxSweepBatch);
  batch_channel_ = Matrix::Zero(num_loads, kMaxSweepBatch);
  batch_trace_ = Matrix::Zero(num_rows, kMaxSweepBatch);
  SetModuli(NominalModuli());
  // The point loads' values of a batch, for G's rows and H^T's (built by SetModuli).
  batch_load_values_ = Matrix::Zero(
      std::max(load_columns_.num_point_loads(), observation_columns_.num_point_loads()),
      kMaxSweepBatch);
}

void MatrixMcreProblem::SetModuli(const Vector& zone_moduli) {
  assert(zone_moduli.size() == static_cast<Eigen::Index>(model_.zones.size()) &&
         zone_moduli.minCoeff() > 0.0);
  if (moduli_.size() == zone_moduli.size() && moduli_ == zone_moduli) return;
  moduli_ = zone_moduli;
  // K = sum_z (E_z / E_z,nom) K_z, the held dofs decoupled (docs/formulation.md section 7).
  stiffness_ = model_.Stiffness(moduli_);
  if (!held_.empty()) stiffness_ = WithHeldDofs(std::move(stiffness_), held_);
  if (num_reactions_ > 0) {
    // r(U) = g^T K(E) U: the rows sum_z E_z (g^T K_z / E_z,nom), below the fixed rows.
    reactions_ = moduli_[0] * reaction_zone_rows_[0];
    for (std::size_t z = 1; z < reaction_zone_rows_.size(); ++z) {
      reactions_ += moduli_[static_cast<Eigen::Index>(z)] * reaction_zone_rows_[z];
    }
    // By rows for r(U_j) in the time loops: its few entries, not a pass over n columns.
    reaction_rows_ = reactions_;
    const int num_fixed = static_cast<int>(fixed_observation_.rows());
    std::vector<Eigen::Triplet<double>> entries;
    for (const SparseMatrix* part : {&fixed_observation_, &reactions_}) {
      const int offset = part == &reactions_ ? num_fixed : 0;
      for (int outer = 0; outer < part->outerSize(); ++outer) {
        for (SparseMatrix::InnerIterator it(*part, outer); it; ++it) {
          entries.emplace_back(offset + static_cast<int>(it.row()), static_cast<int>(it.col()),
                               it.value());
        }
      }
    }
    observation_.resize(num_fixed + num_reactions_, model_.dofs());
    observation_.setFromTriplets(entries.begin(), entries.end());
    observation_transposed_ = observation_.transpose();
    observation_columns_ = SparseColumns(observation_transposed_);
  }
  ThetaIntegratorOptions options;
  options.time_step = time_step_;
  options.theta = theta_;
  options.factorization = factorization_;
  integrator_.Init(mass_, stiffness_, options);
}

void MatrixMcreProblem::DirectSweep(const Matrix& retrograde, bool include_data,
                                    Matrix* displacement) {
  const int n = num_nodes(), m = num_steps();
  assert(retrograde.rows() == n && retrograde.cols() == m + 1);
  displacement->resize(n, m + 1);
  // From rest: U_0 = V_0 = 0.
  displacement->col(0).setZero();
  velocity_[0].setZero();
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    // W_theta = theta W_{k+1} + (1 - theta) W_k.
    shift_ = theta_ * retrograde.col(k + 1) + (1.0 - theta_) * retrograde.col(k);
    DirectStep(k, include_data, retrograde.col(k).data(), retrograde.col(k + 1).data(),
               velocity_[current], displacement->col(k), velocity_[next], displacement->col(k + 1));
  }
  ++sweep_count_;
}

void MatrixMcreProblem::RetrogradeSweep(const Matrix& displacement, bool include_data,
                                        Matrix* retrograde) {
  const int n = num_nodes(), m = num_steps();
  assert(displacement.rows() == n && displacement.cols() == m + 1);
  retrograde->resize(n, m + 1);
  // From rest at T: (v_m, omega_m) = (0, 0), in reversed time.
  velocity_[0].setZero();
  state_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    // Step t_j -> t_{j-1} carries c_j H^T diag(beta) (H U_j - d~_j).
    observation_columns_.TransposeMultiply(displacement.col(j).data(), trace_.data());
    RetrogradeStep(j, include_data, velocity_[current], state_[current], velocity_[next],
                   state_[next]);
    // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j, omega_m = 0.
    retrograde->col(j) =
        (theta_ * state_[next] + (1.0 - theta_) * state_[current]) * (1.0 / QuadratureWeight(j));
  }
  // W_0 = (1 - theta) omega_0 / c_0 (omega_{-1} = 0).
  retrograde->col(0) = ((1.0 - theta_) / QuadratureWeight(0)) * state_[m & 1];
  ++sweep_count_;
}

double MatrixMcreProblem::InnerProduct(const Matrix& x, const Matrix& y) {
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h x_j^T (K + G diag(1/alpha) G^T) y_j.
    sum += QuadratureWeight(j) * h * PenaltyForm(j, x.col(j), y.col(j));
  }
  return sum;
}

double MatrixMcreProblem::Cost(const Matrix& displacement, const Matrix& retrograde) {
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h [1/2 W^T K W + 1/2 (G^T W)^T diag(a_j / alpha) G^T W
    //        + 1/2 (H U - d~)^T diag(beta) (H U - d~)].
    const double* w = retrograde.col(j).data();
    const double gap = StiffnessForm(w, w);
    load_columns_.TransposeMultiply(w, channel_.data());
    MaskInactiveLoads(j, channel_);
    observation_columns_.TransposeMultiply(displacement.col(j).data(), trace_.data());
    trace_ -= measured_outputs_.col(j);
    const double integrand = 0.5 * gap + 0.5 * channel_.cwiseQuotient(alphas_).dot(channel_) +
                             0.5 * betas_.dot(trace_.cwiseProduct(trace_));
    sum += QuadratureWeight(j) * h * integrand;
  }
  return sum;
}

void MatrixMcreProblem::CostGradients(const Matrix& displacement, const Matrix& retrograde,
                                      Vector* gradient) {
  const int zones = static_cast<int>(model_.zones.size());
  const double h = time_step();
  gradient->setZero(zones);
  for (int j = 0; j <= num_steps(); ++j) {
    shift_ = retrograde.col(j) + 2.0 * displacement.col(j);
    for (int z = 0; z < zones; ++z) {
      // -(1/(2 E_z,nom)) c_j h W_j^T K_z (W_j + 2 U_j).
      (*gradient)[z] += -0.5 * QuadratureWeight(j) * h *
                        zone_forms_[z](retrograde.col(j).data(), shift_.data()) /
                        model_.zones[z].nominal_modulus;
    }
    if (num_reactions_ == 0) continue;
    // Trusted: c_j h alpha_r sum_s (r_s(U_j) - f~_sj) g_s^T K_z U_j / E_z,nom, the bar's
    // alpha_r (r(U_j) / E_1) (r(U_j) - f0~_j) (docs/formulation.md section 7).
    FormReactionMisfit(j, displacement.col(j));
    for (int z = 0; z < zones; ++z) {
      (*gradient)[z] += QuadratureWeight(j) * h * reaction_weight_ *
                        reaction_zone_forms_[z](reaction_trace_.data(), displacement.col(j).data());
    }
  }
}

Vector MatrixMcreProblem::ZoneErrorMap(const Matrix& retrograde) {
  const int zones = static_cast<int>(model_.zones.size());
  const double h = time_step();
  Vector map = Vector::Zero(zones);
  for (int j = 0; j <= num_steps(); ++j) {
    for (int z = 0; z < zones; ++z) {
      // (E_z / E_z,nom) c_j h 1/2 W_j^T K_z W_j.
      map[z] += (moduli_[z] / model_.zones[z].nominal_modulus) * QuadratureWeight(j) * h * 0.5 *
                zone_forms_[z](retrograde.col(j).data(), retrograde.col(j).data());
    }
  }
  return map;
}

Vector MatrixMcreProblem::DofErrorMap(const Matrix& retrograde) {
  const double h = time_step();
  Vector map = Vector::Zero(num_nodes());
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h 1/2 W_ij (K W_j)_i.
    product_.noalias() = stiffness_ * retrograde.col(j);
    map += (0.5 * QuadratureWeight(j) * h) * retrograde.col(j).cwiseProduct(product_);
  }
  return map;
}

void MatrixMcreProblem::ElementSensitivities(const Matrix& displacement, const Matrix& retrograde,
                                             Vector* sensitivity) {
  assert(!model_.elements.empty());
  const double h = time_step();
  sensitivity->setZero(static_cast<Eigen::Index>(model_.elements.size()));
  for (int j = 0; j <= num_steps(); ++j) {
    const double weight = QuadratureWeight(j) * h;
    // -c_j h (E_z / E_z,nom) (1/2 W_j^T K_el W_j + W_j^T K_el U_j).
    AddSampleElementMaps(model_, moduli_, displacement.col(j).data(), retrograde.col(j).data(),
                         weight, nullptr, sensitivity);
    if (num_reactions_ == 0) continue;
    FormReactionMisfit(j, displacement.col(j));
    AddSampleReactionSensitivities(displacement.col(j).data(), weight, sensitivity);
  }
}

void MatrixMcreProblem::FormReactionMisfit(int j, const Eigen::Ref<const Vector>& displacement) {
  // r(U_j) - f~_j, the trusted supports' reactions against their data.
  reaction_trace_.noalias() = reaction_rows_ * displacement;
  reaction_trace_ -= measured_outputs_.col(j).tail(num_reactions_);
}

void MatrixMcreProblem::AddSampleReactionSensitivities(const double* displacement, double weight,
                                                       Vector* sensitivity) const {
  for (const auto& [support, el] : reaction_elements_) {
    const MatrixModelElement& element = model_.elements[static_cast<std::size_t>(el)];
    const double zone_factor = moduli_[element.zone] /
                               model_.zones[static_cast<std::size_t>(element.zone)].nominal_modulus;
    // c_j h alpha_r (E_z / E_z,nom) (r_s(U_j) - f~_sj) phi_s^T K_el U_j (CostGradients).
    (*sensitivity)[el] +=
        weight * reaction_weight_ * zone_factor * reaction_trace_[support] *
        ElementBilinearForm(element, TrustedReactionTest(model_.supports[support]).data(),
                            displacement);
  }
}

SparseMatrix MatrixMcreProblem::PenaltyMatrix() const {
  // P = K + G diag(1/alpha) G^T.
  const SparseMatrix scaled = loads_ * alphas_.cwiseInverse().asDiagonal();
  return stiffness_ + SparseMatrix(scaled * loads_transposed_);
}

SparseMatrix MatrixMcreProblem::PenaltyMatrixAt(int j) const {
  if (load_active_.size() == 0) return PenaltyMatrix();
  // P_j = K + G diag(a_j / alpha) G^T.
  const SparseMatrix scaled = loads_ * load_active_.col(j).cwiseQuotient(alphas_).asDiagonal();
  return stiffness_ + SparseMatrix(scaled * loads_transposed_);
}

SparseMatrix MatrixMcreProblem::WeightedObservation() const {
  // H^T diag(beta) H.
  const SparseMatrix weighted = observation_transposed_ * betas_.asDiagonal();
  return SparseMatrix(weighted * observation_);
}

void MatrixMcreProblem::WeightedData(int j, Eigen::Ref<Vector> load) const {
  // H^T diag(beta) d~_j.
  load.noalias() = observation_transposed_ * betas_.cwiseProduct(measured_outputs_.col(j));
}

void MatrixMcreProblem::MeasuredForce(int j, Eigen::Ref<Vector> load) const {
  // G F~_j.
  load.noalias() = loads_ * measured_loads_.col(j);
}

double MatrixMcreProblem::RestCost() {
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h [1/2 F~^T diag(alpha) F~ + 1/2 d~^T diag(beta) d~].
    sum += QuadratureWeight(j) * time_step() * 0.5 *
           (alphas_.dot(measured_loads_.col(j).cwiseAbs2()) +
            betas_.dot(measured_outputs_.col(j).cwiseAbs2()));
  }
  return sum;
}

Vector MatrixMcreProblem::NominalModuli() const { return model_.NominalModuli(); }

template <typename Observe>
void MatrixMcreProblem::DataResponseSweep(Observe&& observe) {
  const int m = num_steps();
  // From rest: U_0 = V_0 = 0.
  stream_velocity_[0].setZero();
  stream_displacement_[0].setZero();
  observe(0, stream_displacement_[0]);
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    // DirectSweep's step at W = 0: f_theta = G F~_theta (the same operations, so the
    // same bits).
    shift_.setZero();
    DirectStep(k, true, shift_.data(), shift_.data(), stream_velocity_[current],
               stream_displacement_[current], stream_velocity_[next], stream_displacement_[next]);
    observe(k + 1, stream_displacement_[next]);
  }
  ++sweep_count_;
}

ChannelSet MatrixMcreProblem::ModelChannels(const CoupledSolution& solution) const {
  const int m = num_steps();
  // G^T W and H U from the stored fields, or as the streaming solve kept them.
  const Matrix load_retrograde = solution.has_fields()
                                     ? Matrix(loads_transposed_ * solution.retrograde)
                                     : solution.load_retrograde;
  const Matrix outputs =
      solution.has_fields() ? Matrix(observation_ * solution.displacement) : solution.traces;
  assert(load_retrograde.rows() == alphas_.size() && load_retrograde.cols() == m + 1 &&
         outputs.rows() == num_traces() && outputs.cols() == m + 1);
  ChannelSet set;
  set.time_step = time_step_;
  for (std::size_t c = 0; c < load_channels_.size(); ++c) {
    const auto row = static_cast<Eigen::Index>(c);
    // F_c = F~_c - a_c (G^T W)_c / alpha_c, the direct sweep's load (docs/matrix_models.md
    // section 2; an unmeasured load's F~ = 0, a = 0 where it does not act).
    Vector force = (measured_loads_.row(row) - load_retrograde.row(row) / alphas_[row]).transpose();
    if (load_active_.size() > 0) force.array() *= load_active_.row(row).transpose().array();
    set.Add(load_channels_[c], ChannelKind::kForce, force);
  }
  for (std::size_t k = 0; k < output_channels_.size(); ++k) {
    if (output_channels_[k].empty()) continue;  // a datum 0
    set.Add(output_channels_[k], output_kinds_[k],
            outputs.row(static_cast<Eigen::Index>(k)).transpose());
  }
  // The supports' displacement channels that are not rows of H. Their rows, after the
  // sensors' in the supports' order: measured, the displacement channel's; pinned, the
  // data 0 of its dofs (ObservedRows).
  auto row = static_cast<Eigen::Index>(model_.sensors.size());
  for (const MatrixModelSupport& support : model_.supports) {
    const bool has_channel = !support.displacement_channel.empty();
    if (treatment_ == ClampModel::kMeasured) {
      if (has_channel) ++row;
      continue;
    }
    const Eigen::Index first_datum = row;
    if (treatment_ == ClampModel::kPinned) row += static_cast<Eigen::Index>(support.dofs.size());
    if (!has_channel) continue;
    Vector displacement = Vector::Zero(m + 1);  // trusted: held at rest
    if (treatment_ == ClampModel::kPinned) {
      // g^T U / (g^T g), U_i of each dof i from its datum row e_i^T U.
      for (std::size_t d = 0; d < support.dofs.size(); ++d) {
        displacement += support.reaction[support.dofs[d]] *
                        outputs.row(first_datum + static_cast<Eigen::Index>(d)).transpose();
      }
      displacement /= support.reaction.squaredNorm();
    }
    set.Add(support.displacement_channel, ChannelKind::kDisplacement, displacement);
  }
  return set;
}

Matrix MatrixMcreProblem::ModelOutputs() {
  const auto sensors = static_cast<Eigen::Index>(model_.sensors.size());
  Matrix outputs(sensors, num_steps() + 1);
  DataResponseSweep([&](int j, const Vector& displacement) {
    observation_columns_.TransposeMultiply(displacement.data(), trace_.data());
    outputs.col(j) = trace_.head(sensors);
  });
  return outputs;
}

void MatrixMcreProblem::DataResponseTraces(Matrix* traces) {
  traces->resize(num_traces(), num_steps() + 1);
  DataResponseSweep([&](int j, const Vector& displacement) {
    observation_columns_.TransposeMultiply(displacement.data(), traces->col(j).data());
  });
}

Matrix MatrixMcreProblem::ModelSupportForces() {
  assert(num_reactions_ == static_cast<int>(model_.supports.size()));
  Matrix forces(num_reactions_, num_steps() + 1);
  DataResponseSweep([&](int j, const Vector& displacement) {
    // r_s(U_j) = g_s^T K(E) U_j.
    reaction_trace_.noalias() = reaction_rows_ * displacement;
    forces.col(j) = reaction_trace_;
  });
  return forces;
}

}  // namespace mcrewave
