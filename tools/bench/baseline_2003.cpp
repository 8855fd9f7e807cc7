// The 2003 baseline of tethash_bench (baseline_2003.hpp).
#include "baseline_2003.hpp"

#include "tethash/detect.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace tethash::bench {
namespace {
/// The hash of the 2003 paper, written here so that the baseline shares no code with the detector it is
/// compared with: (x·73856093 xor y·19349663 xor z·83492791) on 32-bit wrapping integers.
/// The paper's table size: a prime (the smallest ≥ n, n ≥ 2), by trial division.
std::int64_t prime_at_least(std::int64_t n)
{
    for (;; ++n) {
        bool prime = n >= 2;
        for (std::int64_t d = 2; prime && d * d <= n; ++d)
            prime = n % d != 0;
        if (prime) return n;
    }
}

std::uint64_t teschner_hash(std::int32_t x, std::int32_t y, std::int32_t z)
{
    return static_cast<std::uint32_t>(static_cast<std::uint32_t>(x) * 73856093u ^
                                      static_cast<std::uint32_t>(y) * 19349663u ^
                                      static_cast<std::uint32_t>(z) * 83492791u);
}
} // namespace

void Baseline2003::run(const TetMesh& m, double l, std::vector<std::pair<Index, Index>>& out)
{
    const Index n = m.num_vertices();
    if (m_table == 0) {
        m_table = static_cast<std::size_t>(prime_at_least(std::max<Index>(2 * n, 2)));
        m_buckets.assign(m_table, {});
        m_stamp.assign(m_table, 0);
    }
    ++m_step;
    m_cell.resize(3 * static_cast<std::size_t>(n));
    const double inv = 1.0 / l;
    for (Index v = 0; v < n; ++v) {
        const std::int32_t c[3] = {static_cast<std::int32_t>(std::floor(m.positions(v, 0) * inv)),
                                   static_cast<std::int32_t>(std::floor(m.positions(v, 1) * inv)),
                                   static_cast<std::int32_t>(std::floor(m.positions(v, 2) * inv))};
        for (int k = 0; k < 3; ++k)
            m_cell[3 * v + k] = c[k];
        const std::size_t b = teschner_hash(c[0], c[1], c[2]) % m_table;
        if (m_stamp[b] != m_step) {
            m_stamp[b] = m_step;
            m_buckets[b].clear();
        }
        m_buckets[b].push_back(v);
    }
    out.clear();
    for (Index t = 0; t < m.num_tets(); ++t) {
        const Index id[4] = {m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3)};
        Eigen::Vector3d p[4];
        for (int k = 0; k < 4; ++k)
            p[k] = m.positions.row(id[k]).transpose();
        const Eigen::Vector3d lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]).cwiseMin(p[3]);
        const Eigen::Vector3d hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]).cwiseMax(p[3]);
        const Eigen::Vector3d e1 = p[1] - p[0], e2 = p[2] - p[0], e3 = p[3] - p[0];
        const double vol = e1.dot(e2.cross(e3));
        if (vol == 0) continue;
        std::int32_t c0[3], c1[3];
        for (int k = 0; k < 3; ++k) {
            c0[k] = static_cast<std::int32_t>(std::floor(lo[k] * inv));
            c1[k] = static_cast<std::int32_t>(std::floor(hi[k] * inv));
        }
        for (std::int32_t x = c0[0]; x <= c1[0]; ++x)
            for (std::int32_t y = c0[1]; y <= c1[1]; ++y)
                for (std::int32_t z = c0[2]; z <= c1[2]; ++z) {
                    const std::size_t b = teschner_hash(x, y, z) % m_table;
                    if (m_stamp[b] != m_step) continue;
                    for (Index v : m_buckets[b]) {
                        if (v == id[0] || v == id[1] || v == id[2] || v == id[3]) continue;
                        if (m_cell[3 * v] != x || m_cell[3 * v + 1] != y || m_cell[3 * v + 2] != z) continue;
                        const Eigen::Vector3d q = m.positions.row(v).transpose();
                        if ((q.array() < lo.array()).any() || (q.array() > hi.array()).any()) continue;
                        const Eigen::Vector3d d = q - p[0];
                        const double b1 = d.dot(e2.cross(e3)) / vol, b2 = e1.dot(d.cross(e3)) / vol,
                                     b3 = e1.dot(e2.cross(d)) / vol;
                        if (b1 >= 0 && b2 >= 0 && b3 >= 0 && b1 + b2 + b3 <= 1) out.emplace_back(v, t);
                    }
                }
    }
}

bool same_pairs(std::vector<std::pair<Index, Index>> pairs, const std::vector<Contact>& contacts)
{
    if (pairs.size() != contacts.size()) return false;
    std::sort(pairs.begin(), pairs.end());
    for (std::size_t i = 0; i < pairs.size(); ++i)
        if (pairs[i].first != contacts[i].vertex || pairs[i].second != contacts[i].tet) return false;
    return true;
}

} // namespace tethash::bench
