#pragma once
// The one millisecond timer of tethash (private header): the detector's stages, penetration depth, the BSP
// trees' build, and in the layers above (as "core/timing.hpp") the simulator's step stages and the spheres study.
#include <chrono>

namespace tethash::detail {

using Clock = std::chrono::steady_clock;

/// Milliseconds since t0.
inline double ms_since(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

} // namespace tethash::detail
