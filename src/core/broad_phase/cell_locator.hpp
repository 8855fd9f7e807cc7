#pragma once
// The locator of a layout's cells (private header), shared by the portals broad phase (bp_portals.cpp) and the walls
// of the cells (cell_walls.cpp): a uniform grid of buckets over the cells' union box; a cell is listed in the buckets
// of the range cell_coord(lo) .. cell_coord(hi) (clamped), the expression the points use, so a point (a box) in a
// cell finds it in its bucket (range) whatever the rounding (bp_common.hpp).
#include "bp_common.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace tethash::detail {

inline bool boxes_intersect(const Box& a, const Box& b)
{
    for (int k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
    return true;
}

class CellLocator {
  public:
    /// About 8 buckets per cell, at most 64 per axis, shaped like the cells' union.
    void build(const std::vector<Box>& cells);
    /// The first cell (lowest index in its bucket's list) whose closed box contains p, -1 when none.
    Index locate(const std::vector<Box>& cells, const double* p) const
    {
        return locate(p, [&](Index c) {
            const Box& b = cells[static_cast<std::size_t>(c)];
            return in_box(p, b.lo, b.hi);
        });
    }
    /// The first cell of p's bucket (lowest index) that `contains(cell)` accepts, -1 when none. `contains` must
    /// accept only cells whose box holds p.
    template <class Contains> Index locate(const double* p, Contains&& contains) const
    {
        if (m_empty || !in_box(p, m_union.lo, m_union.hi)) return -1;
        const std::size_t k = bucket(coord(0, p[0]), coord(1, p[1]), coord(2, p[2]));
        for (Index i = m_start[k]; i < m_start[k + 1]; ++i) {
            const Index cell = m_cells[static_cast<std::size_t>(i)];
            if (contains(cell)) return cell;
        }
        return -1;
    }
    /// `out` = every cell whose closed box intersects b, each once, ascending.
    void overlapping(const std::vector<Box>& cells, const Box& b, std::vector<Index>& out) const;
    std::int64_t bytes() const { return bytes_of(m_start, m_cells); }

  private:
    /// The bucket coordinate of x on axis a (the monotone cell_coord, clamped to the buckets).
    std::int64_t coord(int a, double x) const
    {
        return m_dims[a] == 1 ? 0 : std::clamp<std::int64_t>(cell_coord(x, m_union.lo[a], m_inv[a]), 0, m_dims[a] - 1);
    }
    std::size_t bucket(std::int64_t x, std::int64_t y, std::int64_t z) const
    {
        return static_cast<std::size_t>((x * m_dims[1] + y) * m_dims[2] + z);
    }

    bool m_empty = true;
    Box m_union{};
    double m_inv[3] = {1, 1, 1};
    std::int64_t m_dims[3] = {1, 1, 1};
    std::vector<Index> m_start, m_cells; // buckets + 1: the cells of bucket k are m_cells[m_start[k], [k + 1])
};

} // namespace tethash::detail
