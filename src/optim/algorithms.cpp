#include "mcrewave/optim/algorithms.h"

#include <vector>

#include "core/enum_names.h"

namespace mcrewave {

bool IsAlgorithmAvailable(OptimizerType optimizer, OuterAlgorithm algorithm, int parameters) {
  switch (algorithm) {
    case OuterAlgorithm::kDefault:
    case OuterAlgorithm::kLbfgs:
      return true;
    case OuterAlgorithm::kBobyqa:
    case OuterAlgorithm::kCobyla:
    case OuterAlgorithm::kSbplx:
    case OuterAlgorithm::kMma:
    case OuterAlgorithm::kSlsqp:
      return optimizer == OptimizerType::kNlopt;
    case OuterAlgorithm::kBrent:
    case OuterAlgorithm::kSecant:
      return optimizer == OptimizerType::kNlopt && parameters == 1;
    case OuterAlgorithm::kBfgs:
      return optimizer == OptimizerType::kCeres;
  }
  return false;
}

OuterAlgorithm ResolveAlgorithm(OptimizerType optimizer, OuterAlgorithm algorithm, int parameters) {
  if (algorithm != OuterAlgorithm::kDefault) return algorithm;
  if (optimizer == OptimizerType::kCeres) return OuterAlgorithm::kLbfgs;
  return parameters == 1 ? OuterAlgorithm::kSecant : OuterAlgorithm::kBobyqa;
}

bool UsesGradient(OptimizerType optimizer, OuterAlgorithm algorithm, int parameters) {
  switch (ResolveAlgorithm(optimizer, algorithm, parameters)) {
    case OuterAlgorithm::kMma:
    case OuterAlgorithm::kLbfgs:
    case OuterAlgorithm::kSlsqp:
    case OuterAlgorithm::kBfgs:
    case OuterAlgorithm::kSecant:
      return true;
    default:
      return false;
  }
}

std::string AvailableAlgorithms(OptimizerType optimizer, int parameters) {
  std::vector<std::string> names;
  for (const auto& [algorithm, name] : kOuterAlgorithmNames) {
    if (IsAlgorithmAvailable(optimizer, algorithm, parameters)) names.push_back(name);
  }
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + names[i];
  }
  return text;
}

}  // namespace mcrewave
