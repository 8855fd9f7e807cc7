// Brute force as a broad phase: every vertex against every tet box, with the vertices sorted by x once per call so
// that each tet only looks at the vertices of its x-extent (the oracle's layout; still every pair that can touch).
#include "bp_brute_force.hpp"

#include "team.hpp"

#include <algorithm>
#include <chrono>

namespace tethash::detail {

BroadPhaseTimes BruteForce::find(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    using Clock = std::chrono::steady_clock;
    BroadPhaseTimes times;
    const auto t0 = Clock::now();
    const Index n = s.num_vertices;
    m_order.resize(static_cast<std::size_t>(n));
    for (Index v = 0; v < n; ++v)
        m_order[static_cast<std::size_t>(v)] = v;
    const double* P = s.positions;
    std::sort(m_order.begin(), m_order.end(), [P](Index a, Index b) {
        const double xa = P[3 * static_cast<std::size_t>(a)], xb = P[3 * static_cast<std::size_t>(b)];
        return xa < xb || (xa == xb && a < b);
    });
    m_xs.resize(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i)
        m_xs[static_cast<std::size_t>(i)] = P[3 * static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)])];
    m_static.assign(static_cast<std::size_t>(n), 0);
    for (Index v : s.static_vertices)
        m_static[static_cast<std::size_t>(v)] = 1;
    const auto t1 = Clock::now();
    times.ms_build = std::chrono::duration<double, std::milli>(t1 - t0).count();

    const int T = static_cast<int>(sinks.size());
#pragma omp parallel num_threads(T) if (T > 1)
    {
        std::vector<CandidatePair>& out = sinks[static_cast<std::size_t>(team_rank())].pairs;
#pragma omp for schedule(dynamic, 256)
        for (Index t = 0; t < s.num_tets; ++t) {
            double lo[3], hi[3];
            tet_box(s, t, lo, hi);
            const bool tet_static = s.tet_static[t] != 0;
            const auto first = std::lower_bound(m_xs.begin(), m_xs.end(), lo[0]) - m_xs.begin();
            const auto last = std::upper_bound(m_xs.begin(), m_xs.end(), hi[0]) - m_xs.begin();
            for (auto i = first; i < last; ++i) {
                const Index v = m_order[static_cast<std::size_t>(i)];
                const double* p = P + 3 * static_cast<std::size_t>(v);
                if (p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2]) continue;
                if (tet_static && m_static[static_cast<std::size_t>(v)]) continue;
                out.push_back({v, t});
            }
        }
    }
    times.ms_query = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    return times;
}

std::int64_t BruteForce::memory_bytes() const
{
    return static_cast<std::int64_t>(m_order.capacity() * sizeof(Index) + m_xs.capacity() * sizeof(double) +
                                     m_static.capacity());
}

} // namespace tethash::detail
