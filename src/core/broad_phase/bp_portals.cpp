// Cells and portals as a broad phase (docs/partitions.md, portals.hpp): the world divided into convex cells joined by
// portals; each point (vertex, tet box centre) belongs to one cell, kept across calls and followed through the
// portals by a segment test from its previous position; each tet box is tested against the vertices of the cells it
// overlaps (its own, and the adjoining ones whose portal, or wall, it reaches).
//
// Convex cells (a box cut by half-spaces, portals.hpp) keep the argument below with "closed box" read as "the cell as
// contains_cell decides it" (in its box and every rounded n · p − d <= 0: a point in the cell is in its box), boxes
// entered in every cell whose box they meet, and the covering test made conservative: a part of B in convex cells
// only counts as outside unless B lies in one convex cell with a margin no rounding crosses (inside_convex); the
// fast path is for layouts of boxes only.
//
// Why no pair is missed. Cells are closed boxes with non-empty, pairwise disjoint interiors; the "outside" cell (index
// = number of cells) holds the points in no closed cell. (1) Every vertex is assigned one cell that contains it
// (closed): the tracked cell when the point still lies in it, else the cell its segment walk ends in when that cell
// contains it, else the first cell the locator finds (outside when none does). Whatever the rounding of a walk, the
// final containment test decides, so the assignment is always a containing cell. (2) Every tet box B is entered in
// every cell whose closed box intersects B, and in the outside cell when some point of B lies in no cell (the exact
// covering test below). Its home cell (the one holding its centre) only serves the fast path: a box strictly inside
// its home cell intersects no other closed cell (the interiors do not overlap, and a box that touches a neighbour's
// face is not strictly inside) and has no point outside. (3) A vertex v in B lies in its cell c (1); then B
// intersects c (v is in both), so B was entered in c (2), and the query of (c, B) scans the vertices of c's slabs
// that B spans, in B's x-range (query_phase).
// A vertex is in one cell and a box entered at most once per cell, so each pair is found once. Portals and walls thus
// play the same role for exactness; portals make the tracking cheap (a point leaving its room through a door is found
// in the next room by the walk, without a locator query).
//
// The covering test: the cells intersecting B cut each axis of B at their borders into points and open intervals; the
// product pieces are each inside a cell or disjoint from its interior (no border crosses a piece), so B has a point in
// no cell iff one piece is in no cell, and a piece [a, b] (a == b for a point) is in a cell iff lo ≤ a and b ≤ hi on
// every axis.
//
// The locator: cell_locator.hpp.
#include "bp_common.hpp"
#include "cell_locator.hpp"
#include "convex_cells.hpp"

#include "tethash/portals.hpp"

#include <algorithm>
#include <cmath>

namespace tethash::detail {

namespace {

bool contains_point(const Box& b, const double* p)
{
    return in_box(p, b.lo, b.hi);
}

bool strictly_inside(const Box& outer, const Box& inner)
{
    for (int a = 0; a < 3; ++a)
        if (!(outer.lo[a] < inner.lo[a] && inner.hi[a] < outer.hi[a])) return false;
    return true;
}

/// The slabs of a cell: `count` slices across `axis` (y or z), [first, first + count) in the bucket numbering.
struct Slabs {
    int axis = 1;
    double origin = 0, inv = 0; ///< slab of x: cell_coord(x, origin, inv), clamped to 0 .. count - 1
    Index first = 0, count = 1;
    Index slab(double x) const
    {
        return count == 1 ? 0 : static_cast<Index>(std::clamp<std::int64_t>(cell_coord(x, origin, inv), 0, count - 1));
    }
};

struct PortalFace {
    Box rect;         ///< the portal's rectangle (flat on `axis`), or its polygon's bounding box when `general`
    int axis = 0;     ///< the face's axis
    bool upper{};     ///< on the cell's hi face (true) or lo face
    bool general{};   ///< a polygon, or a portal of a convex cell: matched by its box grown by `slack`
    double slack = 0; ///< 1e-9 of the coordinates' magnitude
    Index to = 0;     ///< the cell on the other side
};

class Portals final : public BroadPhaseBase {
  public:
    std::int64_t nodes() const override { return static_cast<std::int64_t>(m_cells.size()); }
    void add_counters(DetectStats& s) const override
    {
        s.ray_tests = m_ray_tests;
        s.portal_overlaps = m_overlaps;
    }

    static constexpr int max_hops = 64;
    /// Vertices per slab the cells aim at by default (PartitionParams::leaf_size): a cell of n vertices has about
    /// sqrt(n / slab_vertices) slabs, at most 256.
    static constexpr double slab_vertices = 16;

  private:
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t structure_bytes() const override
    {
        std::int64_t m = bytes_of(m_cells, m_face_start, m_faces, m_vcell, m_vold, m_tcell, m_told, m_slabs, m_vbucket,
                                  m_vstart, m_vids, m_vx, m_vyz, m_boxes, m_reg_start, m_reg_tets) +
                         m_locator.bytes();
        for (const auto& r : m_thread_regs)
            m += bytes_of(r);
        return m;
    }

    void set_layout(const CellLayout& layout);
    /// The cells of the method's own making over the vertices' box (no layout given).
    void make_own_layout(const PartitionScene& s);
    Index outside() const { return static_cast<Index>(m_cells.size()); }
    /// p in cell c: in its box and, for a convex cell, n · p − d ≤ 0 (as rounded) for each of its planes.
    bool contains_cell(Index c, const double* p) const
    {
        const Box& b = m_cells[static_cast<std::size_t>(c)];
        if (!in_box(p, b.lo, b.hi)) return false;
        for (const CellPlane& pl : m_planes[static_cast<std::size_t>(c)])
            if (pl.n[0] * p[0] + pl.n[1] * p[1] + pl.n[2] * p[2] - pl.d > 0) return false;
        return true;
    }
    /// The first cell (lowest index in its bucket's list) containing p, outside() when none.
    Index locate(const double* p) const
    {
        const Index c = m_locator.locate(p, [&](Index cell) { return contains_cell(cell, p); });
        return c < 0 ? outside() : c;
    }
    /// b lies in the convex cell c with a margin that no rounding of contains_cell can cross: every point of b is in c.
    bool inside_convex(const Box& b, Index c) const;
    /// The cell of a point at p that was in cell `from` at `old`: `from` when it still contains p, else the walk of the
    /// segment old → p through the portals, else locate(). Counts a segment test in `rays`.
    Index follow(Index from, const double* old, const double* p, std::int64_t& rays) const;
    /// Appends every cell intersecting b (each once, ascending) and outside() when b has a point in no cell.
    void overlapped_cells(const Box& b, std::vector<Index>& out, std::vector<Index>& scratch) const;
    bool covered(const Box& b, const std::vector<Index>& cells) const;

    std::vector<Box> m_cells;
    std::vector<std::vector<CellPlane>> m_planes; // per cell: its half-spaces beyond its box (none for a box cell)
    bool m_convex = false;                        // some cell has planes
    std::vector<Index> m_face_start; // cells + 1: the portals of cell c are m_faces[m_face_start[c], [c + 1])
    std::vector<PortalFace> m_faces;
    bool m_own = false; // the layout is of our making (rebuilt when too many vertices leave it)
    CellLocator m_locator;
    // Tracking across calls.
    bool m_tracked = false;
    std::vector<Index> m_vcell, m_tcell; // per vertex, per tet: its cell
    std::vector<double> m_vold, m_told;  // positions, centres at the last call (3 per item)
    // This call.
    std::vector<Slabs> m_slabs;                                      // per cell (the outside cell last)
    std::vector<Index> m_vbucket;                                    // per vertex: its slab
    std::vector<Index> m_vstart, m_vids;                             // slabs + 1: vertices by slab, by x within a slab
    std::vector<double> m_vx;                                        // their x
    std::vector<double> m_vyz;                                       // their y and z (2 per vertex)
    std::vector<Box> m_boxes;                                        // per tet
    std::vector<std::vector<std::pair<Index, Index>>> m_thread_regs; // per thread: (cell, tet) entries
    std::vector<Index> m_reg_start, m_reg_tets;                      // cells + 2: tets entered in each cell
    std::int64_t m_ray_tests = 0, m_overlaps = 0;
};

void Portals::set_layout(const CellLayout& layout)
{
    const std::size_t n = layout.cells.size();
    m_cells.resize(n);
    m_planes.assign(n, {});
    m_convex = false;
    for (std::size_t c = 0; c < n; ++c) {
        for (int a = 0; a < 3; ++a) {
            m_cells[c].lo[a] = layout.cells[c].lo[a];
            m_cells[c].hi[a] = layout.cells[c].hi[a];
        }
        m_planes[c] = layout.cells[c].planes;
        m_convex = m_convex || !m_planes[c].empty();
    }
    // Portals per cell, both directions.
    m_face_start.assign(n + 1, 0);
    for (const Portal& p : layout.portals) {
        ++m_face_start[static_cast<std::size_t>(p.a) + 1];
        ++m_face_start[static_cast<std::size_t>(p.b) + 1];
    }
    for (std::size_t c = 0; c < n; ++c)
        m_face_start[c + 1] += m_face_start[c];
    m_faces.resize(static_cast<std::size_t>(m_face_start[n]));
    std::vector<Index> fill(m_face_start.begin(), m_face_start.end() - 1);
    for (const Portal& p : layout.portals) {
        const bool general = !p.polygon.empty() || !m_planes[static_cast<std::size_t>(p.a)].empty() ||
                             !m_planes[static_cast<std::size_t>(p.b)].empty();
        const double slack = 1e-9 * std::max(detail::magnitude(layout.cells[static_cast<std::size_t>(p.a)]),
                                             detail::magnitude(layout.cells[static_cast<std::size_t>(p.b)]));
        int axis = 0;
        for (int a = 0; a < 3; ++a)
            if (p.lo[a] == p.hi[a] && (p.lo[a] == m_cells[static_cast<std::size_t>(p.a)].lo[a] ||
                                       p.lo[a] == m_cells[static_cast<std::size_t>(p.a)].hi[a]))
                axis = a;
        for (int side = 0; side < 2; ++side) {
            const Index from = side ? p.b : p.a, to = side ? p.a : p.b;
            PortalFace f;
            std::copy(p.lo, p.lo + 3, f.rect.lo);
            std::copy(p.hi, p.hi + 3, f.rect.hi);
            f.axis = axis;
            f.upper = p.lo[axis] == m_cells[static_cast<std::size_t>(from)].hi[axis];
            f.general = general;
            f.slack = slack;
            f.to = to;
            m_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(from)]++)] = f;
        }
    }
    m_locator.build(m_cells);
}

void Portals::make_own_layout(const PartitionScene& s)
{
    const Box vb = vertex_box(s);
    double lo[3], hi[3], ext[3], scale = 0, largest = 0;
    for (int a = 0; a < 3; ++a) {
        scale = std::max({scale, std::abs(vb.lo[a]), std::abs(vb.hi[a])});
        largest = std::max(largest, vb.hi[a] - vb.lo[a]);
    }
    // A margin of 5 % of the largest extent (moving scenes stay inside for a while), never below the coordinates'
    // rounding, so that every axis has a positive extent.
    const double margin = std::max(0.05 * largest, 1e-9 * (1 + scale));
    for (int a = 0; a < 3; ++a) {
        lo[a] = vb.lo[a] - margin;
        hi[a] = vb.hi[a] + margin;
        ext[a] = hi[a] - lo[a];
    }
    // About 64 tets per cell, at most 16 cells per axis, cells as cubic as the box allows.
    const double target = std::clamp(static_cast<double>(s.num_tets) / 64.0, 1.0, 4096.0);
    const double edge = std::cbrt(ext[0] * ext[1] * ext[2] / target);
    int n[3];
    for (int a = 0; a < 3; ++a)
        n[a] = static_cast<int>(std::clamp(std::round(ext[a] / edge), 1.0, 16.0));
    set_layout(grid_cell_layout(lo, hi, n));
    m_own = true;
}

Index Portals::follow(Index from, const double* old, const double* p, std::int64_t& rays) const
{
    if (from != outside() && contains_cell(from, p)) return from;
    if (from == outside()) {
        // A point outside stays there until the locator finds it in a cell (no portal leads in from outside).
        return locate(p);
    }
    ++rays;
    // The segment old + t (p − old), t in [0, 1], from cell `from`: leave through the face it exits by, into the cell
    // beyond when a portal of that face holds the exit point; stop when the cell holds p.
    const double d[3] = {p[0] - old[0], p[1] - old[1], p[2] - old[2]};
    Index cell = from;
    for (int hop = 0; hop < max_hops; ++hop) {
        const Box& b = m_cells[static_cast<std::size_t>(cell)];
        double t_exit = 2;
        int axis = -1;
        bool upper = false, by_plane = false;
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0) continue;
            const bool up = d[a] > 0;
            const double t = ((up ? b.hi[a] : b.lo[a]) - old[a]) / d[a];
            if (t < t_exit) {
                t_exit = t;
                axis = a;
                upper = up;
            }
        }
        for (const CellPlane& pl : m_planes[static_cast<std::size_t>(cell)]) {
            const double nd = pl.n[0] * d[0] + pl.n[1] * d[1] + pl.n[2] * d[2];
            if (!(nd > 0)) continue;
            const double t = (pl.d - (pl.n[0] * old[0] + pl.n[1] * old[1] + pl.n[2] * old[2])) / nd;
            if (t < t_exit) {
                t_exit = t;
                by_plane = true;
            }
        }
        if ((axis < 0 && !by_plane) || t_exit > 1) break; // p lies beyond no face (rounding): the locator decides
        double q[3];
        for (int a = 0; a < 3; ++a)
            q[a] = old[a] + t_exit * d[a];
        if (!by_plane) q[axis] = upper ? b.hi[axis] : b.lo[axis];
        // The portal holding the exit point: a rectangle of the face left by, or a polygon (or a portal of a convex
        // cell) whose box, grown by its slack, holds it. A wrong guess costs nothing: the cell must hold p below.
        Index next = -1;
        for (Index f = m_face_start[static_cast<std::size_t>(cell)];
             f < m_face_start[static_cast<std::size_t>(cell) + 1]; ++f) {
            const PortalFace& face = m_faces[static_cast<std::size_t>(f)];
            bool hit = false;
            if (face.general) {
                hit = true;
                for (int a = 0; a < 3; ++a)
                    hit = hit && face.rect.lo[a] - face.slack <= q[a] && q[a] <= face.rect.hi[a] + face.slack;
            } else {
                hit = !by_plane && face.axis == axis && face.upper == upper && contains_point(face.rect, q);
            }
            if (hit) {
                next = face.to;
                break;
            }
        }
        if (next < 0) break; // through a wall: the locator decides
        cell = next;
        if (contains_cell(cell, p)) return cell;
    }
    return locate(p);
}

bool Portals::inside_convex(const Box& b, Index c) const
{
    const Box& cb = m_cells[static_cast<std::size_t>(c)];
    for (int a = 0; a < 3; ++a)
        if (b.lo[a] < cb.lo[a] || b.hi[a] > cb.hi[a]) return false;
    double big[3];
    for (int a = 0; a < 3; ++a)
        big[a] = std::max(std::abs(b.lo[a]), std::abs(b.hi[a]));
    for (const CellPlane& pl : m_planes[static_cast<std::size_t>(c)]) {
        // n · x − d is affine: below −margin at the corners, below it in the box; the margin (1e-12 of the terms'
        // magnitude) is far above the rounding of contains_cell's expression at any point of the box.
        const double margin = 1e-12 * (std::abs(pl.n[0]) * big[0] + std::abs(pl.n[1]) * big[1] +
                                       std::abs(pl.n[2]) * big[2] + std::abs(pl.d));
        for (int k = 0; k < 8; ++k) {
            const double x = k & 1 ? b.hi[0] : b.lo[0], y = k & 2 ? b.hi[1] : b.lo[1], z = k & 4 ? b.hi[2] : b.lo[2];
            if (!(pl.n[0] * x + pl.n[1] * y + pl.n[2] * z - pl.d < -margin)) return false;
        }
    }
    return true;
}

bool Portals::covered(const Box& b, const std::vector<Index>& cells) const
{
    // Convex cells: b inside one of them (with its margin); else the box cells alone must cover it (a piece of b
    // covered by convex cells only counts as uncovered: b is then entered in the outside cell too, which is safe).
    if (m_convex) {
        for (Index c : cells)
            if (c != outside() && !m_planes[static_cast<std::size_t>(c)].empty() && inside_convex(b, c)) return true;
    }
    // Pieces per axis: the cut points of b's range [lo, hi] at the cells' borders, as [a, a] points and [a, b]
    // standing for the open interval between two cut points.
    std::vector<double> cuts[3];
    std::vector<std::pair<double, double>> pieces[3];
    for (int a = 0; a < 3; ++a) {
        cuts[a] = {b.lo[a], b.hi[a]};
        for (Index c : cells) {
            if (c == outside() || !m_planes[static_cast<std::size_t>(c)].empty()) continue;
            const Box& cb = m_cells[static_cast<std::size_t>(c)];
            if (cb.lo[a] > b.lo[a] && cb.lo[a] < b.hi[a]) cuts[a].push_back(cb.lo[a]);
            if (cb.hi[a] > b.lo[a] && cb.hi[a] < b.hi[a]) cuts[a].push_back(cb.hi[a]);
        }
        std::sort(cuts[a].begin(), cuts[a].end());
        cuts[a].erase(std::unique(cuts[a].begin(), cuts[a].end()), cuts[a].end());
        for (std::size_t i = 0; i < cuts[a].size(); ++i) {
            pieces[a].emplace_back(cuts[a][i], cuts[a][i]);
            if (i + 1 < cuts[a].size()) pieces[a].emplace_back(cuts[a][i], cuts[a][i + 1]);
        }
    }
    for (const auto& px : pieces[0])
        for (const auto& py : pieces[1])
            for (const auto& pz : pieces[2]) {
                const std::pair<double, double> piece[3] = {px, py, pz};
                bool in_some = false;
                for (Index c : cells) {
                    if (c == outside() || !m_planes[static_cast<std::size_t>(c)].empty()) continue;
                    const Box& cb = m_cells[static_cast<std::size_t>(c)];
                    bool in = true;
                    for (int a = 0; a < 3; ++a)
                        in = in && cb.lo[a] <= piece[a].first && piece[a].second <= cb.hi[a];
                    if (in) {
                        in_some = true;
                        break;
                    }
                }
                if (!in_some) return false;
            }
    return true;
}

void Portals::overlapped_cells(const Box& b, std::vector<Index>& out, std::vector<Index>& scratch) const
{
    m_locator.overlapping(m_cells, b, scratch);
    out.insert(out.end(), scratch.begin(), scratch.end());
    if (!covered(b, scratch)) out.push_back(outside());
}

bool Portals::build_phase(const PartitionScene& s, int threads)
{
    const Index n = s.num_vertices, m = s.num_tets;
    m_ray_tests = m_overlaps = 0;
    if (n == 0 || m == 0) return false;
    const auto un = static_cast<std::size_t>(n), um = static_cast<std::size_t>(m);
    if (m_cells.empty() && !m_own) {
        if (s.params.cells)
            set_layout(*s.params.cells);
        else
            make_own_layout(s);
        m_tracked = false;
    }
    if (m_tracked && (m_vcell.size() != un || m_tcell.size() != um)) m_tracked = false;
    tet_boxes(s, m_boxes, threads);

    // The vertices' cells: followed from the last call, or located.
    m_vcell.resize(un);
    m_vold.resize(3 * un);
    std::vector<std::int64_t> rays(static_cast<std::size_t>(threads), 0);
    for (int pass = 0; pass < 2; ++pass) {
        const bool tracked = m_tracked;
#pragma omp parallel num_threads(threads) if (threads > 1)
        {
            std::int64_t& r = rays[static_cast<std::size_t>(team_rank())];
#pragma omp for schedule(static)
            for (Index v = 0; v < n; ++v) {
                const double* p = s.positions + 3 * static_cast<std::size_t>(v);
                double* old = m_vold.data() + 3 * static_cast<std::size_t>(v);
                Index& c = m_vcell[static_cast<std::size_t>(v)];
                c = tracked ? follow(c, old, p, r) : locate(p);
                std::copy(p, p + 3, old);
            }
        }
        // Cells of our own making are made again when an eighth of the vertices has left them.
        if (pass == 1 || !m_own) break;
        const auto out = std::count(m_vcell.begin(), m_vcell.end(), outside());
        if (out * 8 <= static_cast<std::int64_t>(n)) break;
        make_own_layout(s);
        m_tracked = false;
    }

    // The tets: home cell of the box centre (followed), then the cells each box is entered in.
    m_tcell.resize(um);
    m_told.resize(3 * um);
    const int T = threads;
    m_thread_regs.resize(static_cast<std::size_t>(T));
    std::vector<std::int64_t> overlaps(static_cast<std::size_t>(T), 0);
    const bool tracked = m_tracked;
#pragma omp parallel num_threads(T) if (T > 1)
    {
        const int rank = team_rank();
        auto& regs = m_thread_regs[static_cast<std::size_t>(rank)];
        regs.clear();
        std::int64_t& r = rays[static_cast<std::size_t>(rank)];
        std::int64_t& o = overlaps[static_cast<std::size_t>(rank)];
        std::vector<Index> cells, scratch;
#pragma omp for schedule(static)
        for (Index t = 0; t < m; ++t) {
            const Box& b = m_boxes[static_cast<std::size_t>(t)];
            const double c[3] = {0.5 * (b.lo[0] + b.hi[0]), 0.5 * (b.lo[1] + b.hi[1]), 0.5 * (b.lo[2] + b.hi[2])};
            double* old = m_told.data() + 3 * static_cast<std::size_t>(t);
            Index& home = m_tcell[static_cast<std::size_t>(t)];
            home = tracked ? follow(home, old, c, r) : locate(c);
            std::copy(c, c + 3, old);
            // The fast path needs box cells only (a convex cell's box may reach into its neighbours').
            if (!m_convex && home != outside() && strictly_inside(m_cells[static_cast<std::size_t>(home)], b)) {
                regs.emplace_back(home, t);
                continue;
            }
            cells.clear();
            overlapped_cells(b, cells, scratch);
            for (Index cell : cells)
                regs.emplace_back(cell, t);
            o += static_cast<std::int64_t>(cells.size()) - 1;
        }
    }
    m_tracked = true;
    for (int k = 0; k < T; ++k) {
        m_ray_tests += rays[static_cast<std::size_t>(k)];
        m_overlaps += overlaps[static_cast<std::size_t>(k)];
    }

    // Vertices by cell, each cell cut into slabs across its longer side of y and z, by x within a slab (counting
    // sort, then a sort per slab); tets by cell.
    const std::size_t cells = m_cells.size() + 1;
    std::vector<Index> per_cell(cells, 0);
    Box out_box{{0, 0, 0}, {0, 0, 0}}; // the outside vertices' box (y and z), for the outside cell's slabs
    bool any_out = false;
    for (Index v = 0; v < n; ++v) {
        const Index c = m_vcell[static_cast<std::size_t>(v)];
        ++per_cell[static_cast<std::size_t>(c)];
        if (c != outside()) continue;
        const double* p = s.positions + 3 * static_cast<std::size_t>(v);
        for (int a = 1; a < 3; ++a) {
            out_box.lo[a] = any_out ? std::min(out_box.lo[a], p[a]) : p[a];
            out_box.hi[a] = any_out ? std::max(out_box.hi[a], p[a]) : p[a];
        }
        any_out = true;
    }
    m_slabs.resize(cells);
    const double per_slab = s.params.leaf_size > 0 ? static_cast<double>(s.params.leaf_size) : slab_vertices;
    Index buckets = 0;
    for (std::size_t c = 0; c < cells; ++c) {
        Slabs& sl = m_slabs[c];
        sl.first = buckets;
        sl.count = 1;
        sl.axis = 1;
        sl.origin = 0;
        sl.inv = 0;
        // A cell's slabs span its box, the outside cell's its vertices' box (a box entered there may reach beyond:
        // the clamp keeps its slab range covering every vertex it holds).
        const Box& b = c + 1 < cells ? m_cells[c] : out_box;
        sl.axis = b.hi[2] - b.lo[2] > b.hi[1] - b.lo[1] ? 2 : 1;
        const double extent = b.hi[sl.axis] - b.lo[sl.axis];
        const double k = std::round(std::sqrt(static_cast<double>(per_cell[c]) / per_slab));
        const double count = std::clamp(k, 1.0, 256.0), inv = count / extent;
        if (count > 1 && extent > 0 && std::isfinite(inv)) { // else one slab: every coordinate maps to it
            sl.count = static_cast<Index>(count);
            sl.origin = b.lo[sl.axis];
            sl.inv = inv;
        }
        buckets += sl.count;
    }
    m_vbucket.resize(un);
    m_vstart.assign(static_cast<std::size_t>(buckets) + 1, 0);
    for (Index v = 0; v < n; ++v) {
        const Slabs& sl = m_slabs[static_cast<std::size_t>(m_vcell[static_cast<std::size_t>(v)])];
        const Index b = sl.first + sl.slab(s.positions[3 * static_cast<std::size_t>(v) + sl.axis]);
        m_vbucket[static_cast<std::size_t>(v)] = b;
        ++m_vstart[static_cast<std::size_t>(b) + 1];
    }
    for (Index b = 0; b < buckets; ++b)
        m_vstart[static_cast<std::size_t>(b) + 1] += m_vstart[static_cast<std::size_t>(b)];
    m_vids.resize(un);
    {
        std::vector<Index> fill(m_vstart.begin(), m_vstart.end() - 1);
        for (Index v = 0; v < n; ++v)
            m_vids[static_cast<std::size_t>(fill[static_cast<std::size_t>(m_vbucket[static_cast<std::size_t>(v)])]++)] =
                v;
    }
    const double* P = s.positions;
#pragma omp parallel for num_threads(T) if (T > 1) schedule(dynamic, 16)
    for (Index b = 0; b < buckets; ++b)
        std::sort(m_vids.begin() + m_vstart[static_cast<std::size_t>(b)],
                  m_vids.begin() + m_vstart[static_cast<std::size_t>(b) + 1], [P](Index u, Index w) {
                      const double xu = P[3 * static_cast<std::size_t>(u)], xw = P[3 * static_cast<std::size_t>(w)];
                      return xu < xw || (xu == xw && u < w);
                  });
    m_vx.resize(un);
    m_vyz.resize(2 * un);
    for (std::size_t i = 0; i < un; ++i) {
        const double* p = P + 3 * static_cast<std::size_t>(m_vids[i]);
        m_vx[i] = p[0];
        m_vyz[2 * i] = p[1];
        m_vyz[2 * i + 1] = p[2];
    }

    m_reg_start.assign(cells + 1, 0);
    for (const auto& regs : m_thread_regs)
        for (const auto& [cell, t] : regs)
            ++m_reg_start[static_cast<std::size_t>(cell) + 1];
    for (std::size_t c = 0; c < cells; ++c)
        m_reg_start[c + 1] += m_reg_start[c];
    m_reg_tets.resize(static_cast<std::size_t>(m_reg_start.back()));
    {
        std::vector<Index> fill(m_reg_start.begin(), m_reg_start.end() - 1);
        for (const auto& regs : m_thread_regs)
            for (const auto& [cell, t] : regs)
                m_reg_tets[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell)]++)] = t;
    }
    return true;
}

void Portals::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    // One entry (cell, tet) after the other: the vertices of the cell's slabs the box spans, in the box's x-range,
    // tested against the box. A vertex in the box has its slab in the box's slab range (the same monotone expression
    // for both, clamped to the cell's slabs), so none is missed.
    const std::size_t cells = m_cells.size() + 1;
    std::vector<Index> cell_of_entry(m_reg_tets.size());
    for (std::size_t c = 0; c < cells; ++c)
        std::fill(cell_of_entry.begin() + m_reg_start[c], cell_of_entry.begin() + m_reg_start[c + 1],
                  static_cast<Index>(c));
    const unsigned char* vstatic = m_static.data();
    for_each_index(static_cast<Index>(m_reg_tets.size()), 64, sinks, [&](Index e, std::vector<CandidatePair>& out) {
        const Index t = m_reg_tets[static_cast<std::size_t>(e)];
        const std::size_t c = static_cast<std::size_t>(cell_of_entry[static_cast<std::size_t>(e)]);
        const Box& b = m_boxes[static_cast<std::size_t>(t)];
        const bool tstatic = s.tet_static[t] != 0;
        const Slabs& sl = m_slabs[c];
        const Index s0 = sl.first + sl.slab(b.lo[sl.axis]), s1 = sl.first + sl.slab(b.hi[sl.axis]);
        for (Index slab = s0; slab <= s1; ++slab) {
            const auto first = m_vx.begin() + m_vstart[static_cast<std::size_t>(slab)],
                       last = m_vx.begin() + m_vstart[static_cast<std::size_t>(slab) + 1];
            for (auto it = std::lower_bound(first, last, b.lo[0]); it != last && *it <= b.hi[0]; ++it) {
                const auto i = static_cast<std::size_t>(it - m_vx.begin());
                const double y = m_vyz[2 * i], z = m_vyz[2 * i + 1];
                if (y < b.lo[1] || y > b.hi[1] || z < b.lo[2] || z > b.hi[2]) continue;
                add_candidate(s, m_vids[i], t, tstatic, vstatic, out);
            }
        }
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_portals()
{
    return std::make_unique<Portals>();
}

} // namespace tethash::detail
