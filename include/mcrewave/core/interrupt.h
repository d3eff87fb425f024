// A request to stop long work early, made by a front end that keeps its process alive
// on Ctrl-C (the Python module: a SIGINT handler while it runs the library) and read by
// the loops that can end early:
//   - the optimisers' guard, before every evaluation of an objective (NLopt, Ceres and
//     the zone minimisers);
//   - the global scan, before every sample;
//   - the coupled solvers' iterations (the relaxations, CG and streaming CG).
// Each ends as a failure whose message is kInterruptedMessage, so an identification
// under way unwinds within one inner iteration and reports a failure. The library never
// makes the request itself; `identify` ends its process on the signal instead.
#pragma once

namespace mcrewave {

inline constexpr char kInterruptedMessage[] = "interrupted (a stop was requested)";

// Sets the request. Async-signal-safe (a lock-free atomic store), so a signal handler
// may call it.
void RequestInterrupt() noexcept;
// Clears it (before the work that may be interrupted starts).
void ClearInterrupt() noexcept;
// Whether a stop was requested since the last ClearInterrupt.
bool InterruptRequested() noexcept;

}  // namespace mcrewave
