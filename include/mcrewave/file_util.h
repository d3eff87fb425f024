// Writing result files atomically: a reader never sees a half-written file.
#pragma once

#include <string>

namespace mcrewave {

// Writes content to a temporary file next to path, flushes it, then renames it
// onto path (atomic on POSIX file systems). On failure removes the temporary file,
// leaves any earlier file at path intact and throws std::runtime_error naming path.
void WriteFileAtomically(const std::string& path, const std::string& content);

}  // namespace mcrewave
