#include "mcrewave/core/interrupt.h"

#include <atomic>

namespace mcrewave {
namespace {

std::atomic<bool> interrupt_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free,
              "RequestInterrupt must be callable from a signal handler");

}  // namespace

void RequestInterrupt() noexcept { interrupt_requested.store(true, std::memory_order_relaxed); }

void ClearInterrupt() noexcept { interrupt_requested.store(false, std::memory_order_relaxed); }

bool InterruptRequested() noexcept { return interrupt_requested.load(std::memory_order_relaxed); }

}  // namespace mcrewave
