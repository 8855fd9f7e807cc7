// The hierarchical hash grid of Mirtich 1998 as a broad phase (docs/partitions.md): levels of doubling
// cell size from the detector's cell size, each tet on the finest level where its box spans at most two cells per
// axis, stored once under the cell of its box's min corner in one hash table keyed by (level, cell); each vertex looks
// up, on every occupied level, the 2 × 2 × 2 cells at and below its own.
//
// Level k has cells of edge l·2^k and the cell coordinates cell_coord(x, o, 2^−k / l) (o: the vertices' min corner).
// A tet goes to the finest level k < levels where cell(hi) − cell(lo) ≤ 1 on every axis (with hi − lo ≤ l·2^k that
// holds but for rounding; the test is the exact condition), keyed by (k, cell(lo)). A vertex p in the tet's box has
// cell(lo) ≤ cell(p) ≤ cell(hi) ≤ cell(lo) + 1 (one monotone expression), so the tet is under one of the 2 × 2 × 2
// cells cell(p) − {0, 1}^3 of that level; those cells are distinct and a scan accepts only entries of the very cell
// looked up, so each pair is found once. (Entering each tet in all the 1 to 8 cells it overlaps, so that a vertex
// looks up its own cell only, measured no faster on the random and decade scenes of docs/partitions.md — the query
// within ±10 % — while it took 2.5 to 4 times the memory and 3 times the build time.) Tets still spanning more than two
// cells on the top level (levels capped) are kept apart and matched against the vertices sorted by x (the brute force's
// layout).
#include "bp_common.hpp"

#include <algorithm>
#include <cmath>

namespace tethash::detail {

namespace {

class HierarchicalGrid final : public BroadPhaseBase {
  public:
    /// Occupied levels (plus one when some tets exceed the top level).
    std::int64_t nodes() const override { return m_nodes; }

    static constexpr int max_levels = 32;

  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    /// A tet in the table: its box, level and min-corner cell, so that a scan compares the exact cell.
    struct Entry {
        Box box;
        std::int64_t cell[3];
        Index tet;
        std::int32_t level;
    };
    std::int64_t structure_bytes() const override
    {
        return bytes_of(m_boxes, m_level, m_bucket, m_start, m_entries, m_cell, m_big) + m_sorted.memory_bytes();
    }

    std::int64_t m_nodes = 0;
    double m_origin[3] = {0, 0, 0}; // the vertices' min corner
    double m_inv[max_levels] = {};  // per level k: 2^−k / cell size
    int m_used[max_levels] = {};    // the occupied levels, finest first
    int m_num_used = 0;
    std::uint64_t m_mask = 0; // buckets − 1 (buckets: a power of two)
    std::vector<Box> m_boxes;
    std::vector<std::int32_t> m_level;   // per tet: its level, or -1 when it exceeds the top level
    std::vector<std::uint64_t> m_bucket; // per tet: its bucket
    std::vector<std::int64_t> m_cell;    // per tet: its min-corner cell (3)
    std::vector<Index> m_start;          // buckets + 1
    std::vector<Entry> m_entries;        // by bucket
    std::vector<Index> m_big;            // tets exceeding the top level
    VerticesByX m_sorted;                // with tets beyond the top level: the vertices by x
};

std::uint64_t cell_hash(std::int32_t level, const std::int64_t c[3])
{
    std::uint64_t h = static_cast<std::uint64_t>(c[0]) * 0x9e3779b97f4a7c15ULL;
    h ^= static_cast<std::uint64_t>(c[1]) * 0xc2b2ae3d27d4eb4fULL;
    h ^= static_cast<std::uint64_t>(c[2]) * 0x165667b19e3779f9ULL;
    h ^= static_cast<std::uint64_t>(level) * 0x27d4eb2f165667c5ULL;
    h ^= h >> 31;
    h *= 0xd6e8feb86659fd93ULL;
    h ^= h >> 32;
    return h;
}

bool HierarchicalGrid::build_phase(const PartitionScene& s, int threads)
{
    const Index n = s.num_vertices, m = s.num_tets;
    m_nodes = 0;
    m_num_used = 0;
    m_entries.clear();
    m_big.clear();
    if (n == 0 || m == 0) return false;
    const int levels = s.params.levels > 0 ? std::min(s.params.levels, max_levels) : max_levels;

    const Box box = vertex_box(s);
    std::copy(box.lo, box.lo + 3, m_origin);
    const double* origin = m_origin;
    const double inv0 = 1.0 / s.cell_size;
    double* inv = m_inv;
    for (int k = 0; k < max_levels; ++k)
        inv[k] = std::ldexp(inv0, -k);

    // Each tet's level and min-corner cell.
    tet_boxes(s, m_boxes, threads);
    const std::uint64_t buckets = static_cast<std::uint64_t>(next_power_of_two(2 * static_cast<std::int64_t>(m)));
    m_level.resize(static_cast<std::size_t>(m));
    m_bucket.resize(static_cast<std::size_t>(m));
    m_cell.resize(3 * static_cast<std::size_t>(m));
#pragma omp parallel for num_threads(threads) if (threads > 1) schedule(static)
    for (Index t = 0; t < m; ++t) {
        const Box& b = m_boxes[static_cast<std::size_t>(t)];
        const double extent = std::max({b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]}) * inv0;
        int k = extent > 1 ? std::min(std::ilogb(extent), levels - 1) : 0; // 2^k ≤ extent: no finer level fits
        std::int64_t c[3];
        for (;; ++k) {
            if (k == levels) {
                k = -1;
                break;
            }
            bool fits = true;
            for (int a = 0; a < 3; ++a) {
                c[a] = cell_coord(b.lo[a], origin[a], inv[k]);
                fits = fits && cell_coord(b.hi[a], origin[a], inv[k]) - c[a] <= 1;
            }
            if (fits) break;
        }
        m_level[static_cast<std::size_t>(t)] = k;
        if (k < 0) continue;
        std::copy(c, c + 3, m_cell.begin() + 3 * static_cast<std::ptrdiff_t>(t));
        m_bucket[static_cast<std::size_t>(t)] = cell_hash(k, c) & (buckets - 1);
    }

    // Counting sort of the placed tets by bucket.
    std::uint32_t occupied = 0;
    m_start.assign(static_cast<std::size_t>(buckets) + 1, 0);
    m_mask = buckets - 1;
    for (Index t = 0; t < m; ++t) {
        const std::int32_t k = m_level[static_cast<std::size_t>(t)];
        if (k < 0) {
            m_big.push_back(t);
            continue;
        }
        occupied |= 1u << k;
        ++m_start[static_cast<std::size_t>(m_bucket[static_cast<std::size_t>(t)]) + 1];
    }
    for (std::uint64_t b = 0; b < buckets; ++b)
        m_start[b + 1] += m_start[b];
    m_entries.resize(static_cast<std::size_t>(m_start[buckets]));
    for (Index t = 0; t < m; ++t) {
        const std::int32_t k = m_level[static_cast<std::size_t>(t)];
        if (k < 0) continue;
        Entry& e = m_entries[static_cast<std::size_t>(m_start[m_bucket[static_cast<std::size_t>(t)]]++)];
        e.box = m_boxes[static_cast<std::size_t>(t)];
        std::copy(m_cell.begin() + 3 * static_cast<std::ptrdiff_t>(t),
                  m_cell.begin() + 3 * static_cast<std::ptrdiff_t>(t) + 3, e.cell);
        e.tet = t;
        e.level = k;
    }
    for (std::uint64_t b = buckets; b > 0; --b)
        m_start[b] = m_start[b - 1];
    m_start[0] = 0;
    for (int k = 0; k < max_levels; ++k)
        if (occupied >> k & 1u) m_used[m_num_used++] = k;
    m_nodes = m_num_used + (m_big.empty() ? 0 : 1);
    if (!m_big.empty()) m_sorted.build(s); // the vertices by x for the tets beyond the top level
    return true;
}

void HierarchicalGrid::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    const double* origin = m_origin;
    const double* inv = m_inv;
    const int* used = m_used;
    const int num_used = m_num_used;
    const std::uint64_t mask = m_mask;
    for_each_vertex(s, m_static, sinks, [&](Index v, const double* p, bool vertex_static, auto& out) {
        for (int u = 0; u < num_used; ++u) {
            const int k = used[u];
            std::int64_t c[3];
            for (int a = 0; a < 3; ++a)
                c[a] = cell_coord(p[a], origin[a], inv[k]);
            for (int d = 0; d < 8; ++d) {
                const std::int64_t q[3] = {c[0] - (d & 1), c[1] - (d >> 1 & 1), c[2] - (d >> 2 & 1)};
                const std::uint64_t b = cell_hash(k, q) & mask;
                for (Index i = m_start[b]; i < m_start[b + 1]; ++i) {
                    const Entry& e = m_entries[static_cast<std::size_t>(i)];
                    if (e.level != k || e.cell[0] != q[0] || e.cell[1] != q[1] || e.cell[2] != q[2]) continue;
                    if (!in_box(p, e.box.lo, e.box.hi)) continue;
                    if ((vertex_static && s.tet_static[e.tet]) || own_vertex(s, v, e.tet)) continue;
                    out.push_back({v, e.tet});
                }
            }
        }
    });
    for_each_index(static_cast<Index>(m_big.size()), 16, sinks, [&](Index i, std::vector<CandidatePair>& out) {
        const Index t = m_big[static_cast<std::size_t>(i)];
        m_sorted.find(s, m_boxes[static_cast<std::size_t>(t)], t, s.tet_static[t] != 0, m_static.data(), out);
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_hierarchical_grid()
{
    return std::make_unique<HierarchicalGrid>();
}

} // namespace tethash::detail
