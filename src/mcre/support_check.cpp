#include "mcrewave/mcre/support_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mcrewave/core/format.h"
#include "mcrewave/mcre/modulus_uncertainty.h"

namespace mcrewave {

double SupportCheck::SupportStiffness() const {
  return compliance > 0.0 ? 1.0 / compliance : std::numeric_limits<double>::infinity();
}

std::string SupportCheck::BriefReport() const {
  std::string report = "support '" + support + "': " + displacement_channel + " against " +
                       force_channel + ", t = " + FormatNumber(statistic, kSixDigits) + " (t > " +
                       FormatNumber(threshold, kSixDigits) +
                       " contradicts a rigid support), compliance " +
                       FormatNumber(compliance, kSixDigits) + " m/N";
  if (std::isfinite(SupportStiffness())) {
    report += ", a spring of " + FormatNumber(SupportStiffness(), kSixDigits) + " N/m";
  }
  return report + (contradicted ? ": the data contradict the trusted support"
                                : ": consistent with a rigid support");
}

SupportCheck CheckSupport(const Vector& displacement, const Vector& regressor, double threshold) {
  SupportCheck check;
  check.threshold = threshold;
  check.displacement_std = DifferenceNoiseStd(displacement);
  // c = -<u~, z> / <z, z>, s_c = s_u / ||z||, t = -<u~, z> / (s_u ||z||)
  // (docs/boundaries.md section 2).
  const double force_norm = regressor.norm();
  if (force_norm == 0.0) return check;
  const double product = -displacement.dot(regressor);
  check.compliance = product / (force_norm * force_norm);
  check.compliance_std = check.displacement_std / force_norm;
  if (product == 0.0) return check;
  check.statistic = check.compliance_std > 0.0
                        ? check.compliance / check.compliance_std
                        : std::copysign(std::numeric_limits<double>::infinity(), product);
  check.contradicted = check.statistic > threshold;
  return check;
}

std::vector<SupportCheck> CheckSupports(const MatrixModelData& model, const ChannelSet& raw,
                                        const ChannelSet& regressors, double threshold) {
  std::vector<SupportCheck> checks;
  for (const MatrixModelSupport& support : model.supports) {
    if (support.displacement_channel.empty()) continue;
    const int displacement = raw.Find(support.displacement_channel);
    const int force = regressors.Find(support.force_channel);
    if (displacement < 0 || force < 0) continue;
    SupportCheck check =
        CheckSupport(raw.channels[static_cast<std::size_t>(displacement)].values,
                     regressors.channels[static_cast<std::size_t>(force)].values, threshold);
    check.support = support.name;
    check.displacement_channel = support.displacement_channel;
    check.force_channel = support.force_channel;
    checks.push_back(check);
  }
  return checks;
}

bool AnySupportContradicted(const std::vector<SupportCheck>& checks) {
  for (const SupportCheck& check : checks) {
    if (check.contradicted) return true;
  }
  return false;
}

double SupportSwitchWeight(const std::vector<SupportCheck>& checks, double ramp_start,
                           double threshold) {
  double weight = 0.0;
  for (const SupportCheck& check : checks) {
    const double t = check.statistic;
    // a = (t - t1) / (t2 - t1) in [0, 1]; t1 = t2: the step at t2.
    const double a = t > threshold     ? 1.0
                     : t <= ramp_start ? 0.0
                                       : (t - ramp_start) / (threshold - ramp_start);
    weight = std::max(weight, a);
  }
  return weight;
}

}  // namespace mcrewave
