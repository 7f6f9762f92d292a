// Cooperative cancellation of a render: requestCancel() may be called from any thread (the Python
// module calls it when Ctrl-C arrives while a render runs without the GIL); the progress counters
// (core/progress.h) and the parallel loops (core/parallel.h) then throw Cancelled, so every stage
// of every method stops within one row or one progress step without a check of its own. The flag
// is process-wide: it stops every render in flight, which is what Ctrl-C means. The command line
// never sets it (SIGINT ends the process there).
#pragma once

#include <atomic>
#include <exception>

namespace wedge {

/// Thrown out of a render when cancellation was requested; not a wedge::Error (no bad input).
class Cancelled : public std::exception {
public:
    const char* what() const noexcept override { return "cancelled"; }
};

namespace detail {
inline std::atomic<bool> g_cancelRequested{false};
}

inline void requestCancel() { detail::g_cancelRequested.store(true, std::memory_order_relaxed); }
inline void clearCancel() { detail::g_cancelRequested.store(false, std::memory_order_relaxed); }
inline bool cancelRequested() { return detail::g_cancelRequested.load(std::memory_order_relaxed); }
inline void throwIfCancelled() {
    if (cancelRequested()) throw Cancelled();
}

}  // namespace wedge
