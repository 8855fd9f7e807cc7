#pragma once
// Wall-clock timing of the detector's stages (private header).
#include <chrono>

namespace tethash::detail {

using Clock = std::chrono::steady_clock;

/// Milliseconds since t0.
inline double ms_since(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

} // namespace tethash::detail
