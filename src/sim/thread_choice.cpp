// The run's thread count: every core while they pay, one where they do not (thread_choice.hpp).
#include "thread_choice.hpp"

#include <algorithm>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash::sim::detail {

ThreadChoice::ThreadChoice(int most) : m_most(std::max(1, most)) {}

int ThreadChoice::every_core()
{
#ifdef TETHASH_HAVE_OPENMP
    return std::max(1, omp_get_max_threads());
#else
    return 1;
#endif
}

void ThreadChoice::record(double ms_per_substep)
{
    if (m_most == 1) return;
    if (m_probe_step > 0) {
        // During a probe: its first step is not counted, then its time against the kept count's.
        if (m_probe_step > 1) m_probe_ms += ms_per_substep;
        if (++m_probe_step <= probe_steps) return;
        const double probe = m_probe_ms / (probe_steps - 1);
        m_probe_step = 0;
        m_since = 0;
        m_settle = true;
        if (probe < margin * m_kept_ms) { // a probe starts only once the kept count has a time
            m_kept = m_now;
            m_kept_ms = probe;
            m_interval = min_interval;
            ++m_switches;
        } else {
            m_now = m_kept;
            m_interval = std::min(max_interval, (probe > far_slower * m_kept_ms ? 8 : 2) * m_interval);
        }
        return;
    }
    if (m_settle) {
        m_settle = false;
    } else {
        // A running mean that follows the scene (contacts come and go) over about five steps.
        m_kept_ms = m_kept_ms > 0 ? 0.8 * m_kept_ms + 0.2 * ms_per_substep : ms_per_substep;
    }
    if (++m_since >= m_interval && m_kept_ms > 0) {
        m_now = m_kept == 1 ? m_most : 1;
        m_probe_step = 1;
        m_probe_ms = 0;
    }
}

} // namespace tethash::sim::detail
