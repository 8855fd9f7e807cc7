// Brute force as a broad phase: every vertex against every tet box, with the vertices sorted by x once per call so
// that each tet only looks at the vertices of its x-extent (the oracle's layout; still every pair that can touch).
#include "bp_brute_force.hpp"

namespace tethash::detail {

BroadPhaseTimes BruteForce::find(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    BroadPhaseTimes times;
    const auto t0 = std::chrono::steady_clock::now();
    m_sorted.build(s);
    static_vertex_flags(s, m_static);
    times.ms_build = ms_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    for_each_index(s.num_tets, 256, sinks, [&](Index t, std::vector<CandidatePair>& out) {
        Box b;
        tet_box(s, t, b.lo, b.hi);
        m_sorted.find(s, b, t, s.tet_static[t] != 0, m_static.data(), out);
    });
    times.ms_query = ms_since(t1);
    return times;
}

std::int64_t BruteForce::memory_bytes() const
{
    return m_sorted.memory_bytes() + bytes_of(m_static);
}

} // namespace tethash::detail
