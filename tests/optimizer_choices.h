// The optimiser-and-algorithm pairs the tests sweep, named "<optimizer>_<algorithm>"
// (nlopt_lbfgs), and the bounded minimiser's options for one of them.
#pragma once

#include <string>
#include <tuple>

#include "mcrewave/core/types.h"
#include "mcrewave/optim/bounded_minimizer.h"

namespace mcrewave::testing {

struct OptimizerChoice {
  OptimizerType optimizer;
  OuterAlgorithm algorithm;

  bool operator<(const OptimizerChoice& other) const {
    return std::tie(optimizer, algorithm) < std::tie(other.optimizer, other.algorithm);
  }
  std::string Name() const {
    return std::string(OptimizerTypeToString(optimizer)) + "_" + OuterAlgorithmToString(algorithm);
  }
  // options with this optimiser and algorithm.
  BoundedMinimizerOptions Apply(BoundedMinimizerOptions options) const {
    options.optimizer = optimizer;
    options.algorithm = algorithm;
    return options;
  }
};

inline constexpr OptimizerChoice kNloptLbfgs{OptimizerType::kNlopt, OuterAlgorithm::kLbfgs};
inline constexpr OptimizerChoice kNloptMma{OptimizerType::kNlopt, OuterAlgorithm::kMma};
inline constexpr OptimizerChoice kNloptSlsqp{OptimizerType::kNlopt, OuterAlgorithm::kSlsqp};
inline constexpr OptimizerChoice kNloptBobyqa{OptimizerType::kNlopt, OuterAlgorithm::kBobyqa};
inline constexpr OptimizerChoice kNloptCobyla{OptimizerType::kNlopt, OuterAlgorithm::kCobyla};
inline constexpr OptimizerChoice kNloptSbplx{OptimizerType::kNlopt, OuterAlgorithm::kSbplx};
inline constexpr OptimizerChoice kCeresLbfgs{OptimizerType::kCeres, OuterAlgorithm::kLbfgs};
inline constexpr OptimizerChoice kCeresBfgs{OptimizerType::kCeres, OuterAlgorithm::kBfgs};

}  // namespace mcrewave::testing
