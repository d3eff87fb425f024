// libFuzzer target of the YAML config loader: ParseConfig with --set overrides.
//
// The input is split at NUL bytes: the first part is the YAML text, each further
// part one "key.path=value" override. InputError is the expected answer to bad
// input; anything else escaping ParseConfig (another exception, a crash, a
// sanitizer report, a hang) is a defect.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "mcrewave/app/config.h"
#include "mcrewave/core/types.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t nul = input.find('\0', start);
    parts.push_back(input.substr(start, nul - start));
    if (nul == std::string::npos) break;
    start = nul + 1;
  }
  const std::vector<std::string> overrides(parts.begin() + 1, parts.end());
  try {
    const mcrewave::Config config = mcrewave::ParseConfig(parts[0], "fuzz.yaml", overrides);
    // A config that was accepted writes back to YAML that parses to the same text.
    const std::string yaml = mcrewave::ConfigToYaml(config);
    if (mcrewave::ConfigToYaml(mcrewave::ParseConfig(yaml, "resolved.yaml")) != yaml) {
      __builtin_trap();
    }
  } catch (const mcrewave::InputError&) {
  }
  return 0;
}
