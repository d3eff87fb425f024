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
    const mcrewave::ChannelSet set = mcrewave::ParseMeasurementCsv(text, "fuzz.csv");
    const bool usable =
        set.num_samples() >= 2 && set.Values("uL").size() == set.Values("u0").size() &&
        set.Values("f0").size() == set.Values("u0").size() &&
        set.Values("fL").size() == set.Values("u0").size() && std::isfinite(set.time_step) &&
        set.time_step > 0.0 && std::isfinite(set.start_time) && set.Values("u0").allFinite() &&
        set.Values("uL").allFinite() && set.Values("f0").allFinite() &&
        set.Values("fL").allFinite();
    if (!usable) __builtin_trap();
  } catch (const mcrewave::InputError&) {
  }
  return 0;
}
