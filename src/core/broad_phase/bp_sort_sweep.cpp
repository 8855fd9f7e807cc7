// Sort and sweep as a broad phase (docs/partitions.md): the vertices and the tet boxes sorted on the
// axis of largest variance, the orders kept across calls and repaired by insertion sort (temporal coherence).
//
// The axis is the one of largest variance of the vertex positions; it changes only when another axis's variance
// exceeds the current one's by 20 % (a new axis means a sort from scratch). Both lists keep their order from the last
// call: the keys are refreshed and an insertion sort repairs the order, which costs O(n + moves) for the small motions
// of a simulation step; when the moves exceed 4 per element the list is sorted from scratch instead.
// The sweep walks the tets by increasing low end, a cursor in the vertex list following the low ends: each tet scans
// the vertices from the cursor while their coordinate is ≤ its high end and keeps those in its box on the other two
// axes. Chunks of tets run in parallel, each starting its cursor by a binary search. Each (vertex, tet) pair is looked
// at once, by the tet's scan; comparisons on the closed interval, so boundary points are found.
#include "bp_common.hpp"

#include <algorithm>

namespace tethash::detail {

namespace {

class SortSweep final : public BroadPhaseBase {
  public:
    /// Calls whose orders were repaired by insertion sort, and calls that sorted from scratch (first call, new
    /// axis, or an insertion sort that exceeded its budget of moves).
    BroadPhaseCounts counts() const override { return {m_full, m_incremental}; }

  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    struct Key {
        double x;
        Index id;
    };
    std::int64_t structure_bytes() const override { return bytes_of(m_points, m_tets, m_boxes, m_xyz); }

    int m_axis = -1;
    std::int64_t m_incremental = 0, m_full = 0;
    std::vector<Key> m_points; // vertices by their coordinate on the axis
    std::vector<Key> m_tets;   // tets by their box's low end on the axis
    std::vector<Box> m_boxes;
    std::vector<double> m_xyz; // the vertices' positions in the sorted order
};

bool key_less(double xa, Index a, double xb, Index b)
{
    return xa < xb || (xa == xb && a < b);
}

/// Repairs the order of `keys` (keys refreshed, order from the last call) by insertion sort; false (order
/// unspecified) when more than `budget` moves were needed.
template <class Key> bool insertion_sort(std::vector<Key>& keys, std::int64_t budget)
{
    std::int64_t moves = 0;
    for (std::size_t i = 1; i < keys.size(); ++i) {
        const Key k = keys[i];
        std::size_t j = i;
        while (j > 0 && key_less(k.x, k.id, keys[j - 1].x, keys[j - 1].id)) {
            keys[j] = keys[j - 1];
            --j;
        }
        keys[j] = k;
        moves += static_cast<std::int64_t>(i - j);
        if (moves > budget) return false;
    }
    return true;
}

template <class Key> void full_sort(std::vector<Key>& keys)
{
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) { return key_less(a.x, a.id, b.x, b.id); });
}

bool SortSweep::build_phase(const PartitionScene& s, int threads)
{
    const Index n = s.num_vertices, m = s.num_tets;
    const double* P = s.positions;
    if (n == 0 || m == 0) return false;

    // The axis of largest variance (sums relative to the first vertex: no cancellation far from the origin).
    double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    for (Index v = 0; v < n; ++v)
        for (int a = 0; a < 3; ++a) {
            const double d = P[3 * static_cast<std::size_t>(v) + a] - P[a];
            sum[a] += d;
            sq[a] += d * d;
        }
    double var[3];
    for (int a = 0; a < 3; ++a)
        var[a] = sq[a] / n - (sum[a] / n) * (sum[a] / n);
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (var[a] > var[axis]) axis = a;
    if (!s.first && m_axis >= 0 && !(var[axis] > 1.2 * var[m_axis])) axis = m_axis;
    const bool fresh = s.first || axis != m_axis || m_points.size() != static_cast<std::size_t>(n) ||
                       m_tets.size() != static_cast<std::size_t>(m);
    m_axis = axis;

    tet_boxes(s, m_boxes, threads);
    if (fresh) {
        m_points.resize(static_cast<std::size_t>(n));
        for (Index v = 0; v < n; ++v)
            m_points[static_cast<std::size_t>(v)] = {0, v};
        m_tets.resize(static_cast<std::size_t>(m));
        for (Index t = 0; t < m; ++t)
            m_tets[static_cast<std::size_t>(t)] = {0, t};
    }
    for (Key& k : m_points)
        k.x = P[3 * static_cast<std::size_t>(k.id) + axis];
    for (Key& k : m_tets)
        k.x = m_boxes[static_cast<std::size_t>(k.id)].lo[axis];
    if (fresh) {
        full_sort(m_points);
        full_sort(m_tets);
        ++m_full;
    } else {
        bool ok = insertion_sort(m_points, 4 * static_cast<std::int64_t>(n));
        if (!ok) full_sort(m_points);
        if (!insertion_sort(m_tets, 4 * static_cast<std::int64_t>(m))) {
            full_sort(m_tets);
            ok = false;
        }
        ++(ok ? m_incremental : m_full);
    }
    m_xyz.resize(3 * static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i) {
        const double* p = P + 3 * static_cast<std::size_t>(m_points[static_cast<std::size_t>(i)].id);
        std::copy(p, p + 3, m_xyz.begin() + 3 * static_cast<std::ptrdiff_t>(i));
    }
    return true;
}

void SortSweep::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    // The sweep, in chunks of consecutive tets, on the axis of the build.
    const Index n = s.num_vertices, m = s.num_tets;
    const int axis = m_axis;
    const Index chunk = 512;
    const Index chunks = (m + chunk - 1) / chunk;
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    for_each_index(chunks, 1, sinks, [&](Index k, std::vector<CandidatePair>& out) {
        const Index begin = k * chunk, end = std::min(m, begin + chunk);
        const double first_lo = m_tets[static_cast<std::size_t>(begin)].x;
        Index cursor = static_cast<Index>(std::lower_bound(m_points.begin(), m_points.end(), first_lo,
                                                           [](const Key& key, double x) { return key.x < x; }) -
                                          m_points.begin());
        for (Index i = begin; i < end; ++i) {
            const Index t = m_tets[static_cast<std::size_t>(i)].id;
            const Box& box = m_boxes[static_cast<std::size_t>(t)];
            while (cursor < n && m_points[static_cast<std::size_t>(cursor)].x < box.lo[axis])
                ++cursor;
            const bool tet_static = s.tet_static[t] != 0;
            for (Index j = cursor; j < n; ++j) {
                const double* p = m_xyz.data() + 3 * static_cast<std::size_t>(j);
                if (p[axis] > box.hi[axis]) break;
                if (p[b] < box.lo[b] || p[b] > box.hi[b] || p[c] < box.lo[c] || p[c] > box.hi[c]) continue;
                add_candidate(s, m_points[static_cast<std::size_t>(j)].id, t, tet_static, m_static.data(), out);
            }
        }
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_sort_sweep()
{
    return std::make_unique<SortSweep>();
}

} // namespace tethash::detail
