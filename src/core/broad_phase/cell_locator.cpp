// The locator of a layout's cells (cell_locator.hpp).
#include "cell_locator.hpp"

#include <cmath>

namespace tethash::detail {

void CellLocator::build(const std::vector<Box>& cells)
{
    const std::size_t n = cells.size();
    m_empty = n == 0;
    m_start.assign(2, 0);
    m_cells.clear();
    for (int a = 0; a < 3; ++a) {
        m_dims[a] = 1;
        m_inv[a] = 1;
    }
    if (m_empty) return;
    m_union = cells[0];
    for (const Box& b : cells)
        for (int a = 0; a < 3; ++a) {
            m_union.lo[a] = std::min(m_union.lo[a], b.lo[a]);
            m_union.hi[a] = std::max(m_union.hi[a], b.hi[a]);
        }
    double ext[3], vol = 1;
    for (int a = 0; a < 3; ++a) {
        ext[a] = m_union.hi[a] - m_union.lo[a];
        vol *= ext[a];
    }
    const double edge = std::cbrt(vol / (8.0 * static_cast<double>(n)));
    std::int64_t buckets = 1;
    for (int a = 0; a < 3; ++a) {
        // Extreme extents (overflow, underflow) get one bucket on the axis: every coordinate maps to it.
        const double k = edge > 0 && std::isfinite(edge) ? std::ceil(ext[a] / edge) : 1;
        m_dims[a] = std::isfinite(k) ? static_cast<std::int64_t>(std::clamp(k, 1.0, 64.0)) : 1;
        m_inv[a] = static_cast<double>(m_dims[a]) / ext[a];
        if (!std::isfinite(m_inv[a])) m_dims[a] = 1;
        buckets *= m_dims[a];
    }
    m_start.assign(static_cast<std::size_t>(buckets) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<Index> fill;
        if (pass == 1) {
            for (std::int64_t k = 0; k < buckets; ++k)
                m_start[static_cast<std::size_t>(k) + 1] += m_start[static_cast<std::size_t>(k)];
            m_cells.resize(static_cast<std::size_t>(m_start.back()));
            fill.assign(m_start.begin(), m_start.end() - 1);
        }
        for (std::size_t c = 0; c < n; ++c) {
            std::int64_t lo[3], hi[3];
            for (int a = 0; a < 3; ++a) {
                lo[a] = coord(a, cells[c].lo[a]);
                hi[a] = coord(a, cells[c].hi[a]);
            }
            for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
                for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                    for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
                        const std::size_t k = bucket(x, y, z);
                        if (pass == 0)
                            ++m_start[k + 1];
                        else
                            m_cells[static_cast<std::size_t>(fill[k]++)] = static_cast<Index>(c);
                    }
        }
    }
}

void CellLocator::overlapping(const std::vector<Box>& cells, const Box& b, std::vector<Index>& out) const
{
    out.clear();
    if (m_empty || !boxes_intersect(m_union, b)) return;
    std::int64_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = coord(a, b.lo[a]);
        hi[a] = coord(a, b.hi[a]);
    }
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
            for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
                const std::size_t k = bucket(x, y, z);
                for (Index i = m_start[k]; i < m_start[k + 1]; ++i) {
                    const Index c = m_cells[static_cast<std::size_t>(i)];
                    if (boxes_intersect(cells[static_cast<std::size_t>(c)], b)) out.push_back(c);
                }
            }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

} // namespace tethash::detail
