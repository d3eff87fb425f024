#include "optim/nlopt_results.h"

namespace mcrewave::internal {

std::string NloptResultName(nlopt::result result) {
  switch (result) {
    case nlopt::SUCCESS:
      return "success";
    case nlopt::STOPVAL_REACHED:
      return "stopval reached";
    case nlopt::FTOL_REACHED:
      return "ftol reached";
    case nlopt::XTOL_REACHED:
      return "xtol reached";
    case nlopt::MAXEVAL_REACHED:
      return "maxeval reached";
    case nlopt::MAXTIME_REACHED:
      return "maxtime reached";
    default:
      return "result code " + std::to_string(static_cast<int>(result));
  }
}

bool IsLineSearchStallAfterProgress(const std::exception& error, bool gradient_based,
                                    bool improved, bool stopped_by_objective) {
  return gradient_based && improved && !stopped_by_objective &&
         std::string(error.what()) == "nlopt failure";
}

}  // namespace mcrewave::internal
