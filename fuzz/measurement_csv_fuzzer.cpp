// libFuzzer target of the measurement CSV reader (ParseMeasurementCsv, the
// parser behind ReadMeasurementCsv). InputError is the expected answer to bad
// input; anything else escaping (another exception, a crash, a sanitizer
// report, a hang) is a defect. An accepted file must give a usable set.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "mcrewave/core/types.h"
#include "mcrewave/data/measurement.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream text(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const mcrewave::MeasurementSet set = mcrewave::ParseMeasurementCsv(text, "fuzz.csv");
    const bool usable = set.num_samples() >= 2 && set.uL.size() == set.u0.size() &&
                        set.f0.size() == set.u0.size() && set.fL.size() == set.u0.size() &&
                        std::isfinite(set.time_step) && set.time_step > 0.0 &&
                        std::isfinite(set.start_time) && set.u0.allFinite() && set.uL.allFinite() &&
                        set.f0.allFinite() && set.fL.allFinite();
    if (!usable) __builtin_trap();
  } catch (const mcrewave::InputError&) {
  }
  return 0;
}
