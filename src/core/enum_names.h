// Internal: the lookups behind every XToString / StringToX pair (types.h,
// identification.h). Each enum has one table tying its values to the names
// that travel through YAML and reports; these two functions read it.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>

namespace mcrewave {
namespace internal {

// The name of `value` in `table`; "unknown" when absent (a programmer error
// the table's tests catch).
template <typename Enum, std::size_t N>
const char* ToName(const std::array<std::pair<Enum, const char*>, N>& table, Enum value) {
  for (const auto& [v, name] : table) {
    if (v == value) return name;
  }
  return "unknown";
}

// Sets *value to the enum named `name` and returns true; false (and *value
// unchanged) when no entry of `table` has that name.
template <typename Enum, std::size_t N>
bool FromName(const std::array<std::pair<Enum, const char*>, N>& table, const std::string& name,
              Enum* value) {
  for (const auto& [v, n] : table) {
    if (name == n) {
      *value = v;
      return true;
    }
  }
  return false;
}

}  // namespace internal
}  // namespace mcrewave
