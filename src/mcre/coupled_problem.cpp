#include "mcrewave/mcre/coupled_problem.h"

#include <cassert>

namespace mcrewave {

void CoupledProblem::DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
                                          const std::vector<Matrix*>& displacement) {
  assert(retrograde.size() == displacement.size() &&
         static_cast<int>(retrograde.size()) <= kMaxSweepBatch);
  for (std::size_t b = 0; b < retrograde.size(); ++b) {
    DirectSweep(retrograde[b] != nullptr ? *retrograde[b] : workspace().zero, true,
                displacement[b]);
  }
}

void CoupledProblem::RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
                                              const std::vector<Matrix*>& retrograde) {
  assert(retrograde.size() == displacement.size() &&
         static_cast<int>(displacement.size()) <= kMaxSweepBatch);
  for (std::size_t b = 0; b < displacement.size(); ++b) {
    RetrogradeSweep(displacement[b] != nullptr ? *displacement[b] : workspace().zero, true,
                    retrograde[b]);
  }
}

void CoupledProblem::FixedPointMap(const Matrix& retrograde, Matrix* displacement, Matrix* image) {
  DirectSweep(retrograde, true, displacement);
  RetrogradeSweep(*displacement, true, image);
}

void CoupledProblem::ApplyIterationMap(const Matrix& retrograde, Matrix* scratch_displacement,
                                       Matrix* image) {
  DirectSweep(retrograde, false, scratch_displacement);
  RetrogradeSweep(*scratch_displacement, false, image);
}

CoupledProblem::SolverWorkspace& CoupledProblem::workspace() {
  if (workspace_.zero.rows() != num_nodes() || workspace_.zero.cols() != num_steps() + 1) {
    workspace_.zero = ZeroField();
  }
  return workspace_;
}

}  // namespace mcrewave
