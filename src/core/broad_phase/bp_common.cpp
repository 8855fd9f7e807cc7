// Pieces shared by the grid, sweep and tree broad phases (bp_common.hpp).
#include "bp_common.hpp"

#include <algorithm>

namespace tethash::detail {

void tet_boxes(const PartitionScene& s, std::vector<Box>& boxes, int threads)
{
    boxes.resize(static_cast<std::size_t>(s.num_tets));
    Box* out = boxes.data();
#pragma omp parallel for num_threads(threads) if (threads > 1) schedule(static)
    for (Index t = 0; t < s.num_tets; ++t)
        tet_box(s, t, out[t].lo, out[t].hi);
}

Box vertex_box(const PartitionScene& s)
{
    const double* P = s.positions;
    Box b{{P[0], P[1], P[2]}, {P[0], P[1], P[2]}};
    for (Index v = 1; v < s.num_vertices; ++v)
        for (int a = 0; a < 3; ++a) {
            const double x = P[3 * static_cast<std::size_t>(v) + a];
            b.lo[a] = x < b.lo[a] ? x : b.lo[a];
            b.hi[a] = x > b.hi[a] ? x : b.hi[a];
        }
    return b;
}

void static_vertex_flags(const PartitionScene& s, std::vector<unsigned char>& flags)
{
    flags.assign(static_cast<std::size_t>(s.num_vertices), 0);
    for (Index v : s.static_vertices)
        flags[static_cast<std::size_t>(v)] = 1;
}

void VerticesByX::build(const PartitionScene& s)
{
    const Index n = s.num_vertices;
    const double* P = s.positions;
    order.resize(static_cast<std::size_t>(n));
    for (Index v = 0; v < n; ++v)
        order[static_cast<std::size_t>(v)] = v;
    std::sort(order.begin(), order.end(), [P](Index a, Index b) {
        const double xa = P[3 * static_cast<std::size_t>(a)], xb = P[3 * static_cast<std::size_t>(b)];
        return xa < xb || (xa == xb && a < b);
    });
    xs.resize(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i)
        xs[static_cast<std::size_t>(i)] = P[3 * static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
}

void VerticesByX::find(const PartitionScene& s, const Box& b, Index t, bool skip_static,
                       const unsigned char* vertex_static, std::vector<CandidatePair>& out) const
{
    const auto first = std::lower_bound(xs.begin(), xs.end(), b.lo[0]) - xs.begin();
    const auto last = std::upper_bound(xs.begin(), xs.end(), b.hi[0]) - xs.begin();
    for (auto i = first; i < last; ++i) {
        const Index v = order[static_cast<std::size_t>(i)];
        const double* p = s.positions + 3 * static_cast<std::size_t>(v);
        if (p[1] < b.lo[1] || p[1] > b.hi[1] || p[2] < b.lo[2] || p[2] > b.hi[2]) continue;
        add_candidate(s, v, t, skip_static, vertex_static, out);
    }
}

std::int64_t VerticesByX::memory_bytes() const
{
    return bytes_of(order) + bytes_of(xs);
}

BroadPhaseTimes BroadPhaseBase::find(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    PhaseTimer timer;
    if (!build_phase(s, static_cast<int>(sinks.size()))) return {};
    static_vertex_flags(s, m_static);
    timer.end_build();
    query_phase(s, sinks);
    return timer.end_query();
}

} // namespace tethash::detail
