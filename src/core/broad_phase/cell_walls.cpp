// Cells from static obstacles and the walls of each cell (portals.hpp: cells_from_obstacles, CellWalls).
#include "cell_locator.hpp"

#include "tethash/error.hpp"
#include "tethash/portals.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <tuple>

namespace tethash {

namespace {

detail::Box obstacle_box(const Bsp& b)
{
    detail::Box out{};
    for (int a = 0; a < 3; ++a) {
        out.lo[a] = b.box_lo()[a];
        out.hi[a] = b.box_hi()[a];
    }
    return out;
}

/// At most `max_cuts` of the sorted, distinct `cuts`, evenly chosen, the first and the last always kept.
void thin_out(std::vector<double>& cuts, int max_cuts)
{
    const std::size_t n = cuts.size(), m = static_cast<std::size_t>(max_cuts);
    if (n <= m) return;
    std::vector<double> kept;
    for (std::size_t i = 0; i < m; ++i)
        kept.push_back(cuts[(i * (n - 1)) / (m - 1)]);
    kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
    cuts = std::move(kept);
}

} // namespace

CellLayout cells_from_obstacles(const ObstacleSet& obstacles, const double* lo, const double* hi, int max_cuts)
{
    if (obstacles.size() == 0) throw Error("cells from obstacles: no obstacle to make cells of");
    if (max_cuts < 2)
        throw Error("cells from obstacles: expected at least 2 cuts per axis, got " + std::to_string(max_cuts));
    // The box: the obstacles' boxes and [lo, hi].
    detail::Box box = obstacle_box(obstacles[0]);
    for (Index o = 1; o < obstacles.size(); ++o) {
        const detail::Box b = obstacle_box(obstacles[o]);
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = std::min(box.lo[a], b.lo[a]);
            box.hi[a] = std::max(box.hi[a], b.hi[a]);
        }
    }
    if (lo != nullptr && hi != nullptr)
        for (int a = 0; a < 3; ++a) {
            if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || lo[a] > hi[a])
                throw Error("cells from obstacles: the scene's box must be finite and not inverted");
            box.lo[a] = std::min(box.lo[a], lo[a]);
            box.hi[a] = std::max(box.hi[a], hi[a]);
        }
    // The cuts per axis: the box's faces and the obstacles' vertex coordinates.
    std::vector<double> cuts[3];
    int n[3];
    for (int a = 0; a < 3; ++a) {
        cuts[a] = {box.lo[a], box.hi[a]};
        for (Index o = 0; o < obstacles.size(); ++o) {
            const Positions& v = obstacles[o].vertices();
            for (Eigen::Index i = 0; i < v.rows(); ++i)
                cuts[a].push_back(v(i, a));
        }
        std::sort(cuts[a].begin(), cuts[a].end());
        cuts[a].erase(std::unique(cuts[a].begin(), cuts[a].end()), cuts[a].end());
        thin_out(cuts[a], max_cuts);
        if (cuts[a].size() < 2) throw Error("cells from obstacles: the obstacles' box is flat"); // closed: never
        n[a] = static_cast<int>(cuts[a].size()) - 1;
    }
    const auto piece = [&](int i, int j, int k) {
        return (static_cast<std::size_t>(k) * static_cast<std::size_t>(n[1]) + static_cast<std::size_t>(j)) *
                   static_cast<std::size_t>(n[0]) +
               static_cast<std::size_t>(i);
    };
    const std::size_t pieces =
        static_cast<std::size_t>(n[0]) * static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(n[2]);
    // Each piece: -1 free, else the first obstacle holding its centre.
    std::vector<Index> label(pieces, -1);
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) {
                const Eigen::Vector3d c(
                    0.5 * (cuts[0][static_cast<std::size_t>(i)] + cuts[0][static_cast<std::size_t>(i) + 1]),
                    0.5 * (cuts[1][static_cast<std::size_t>(j)] + cuts[1][static_cast<std::size_t>(j) + 1]),
                    0.5 * (cuts[2][static_cast<std::size_t>(k)] + cuts[2][static_cast<std::size_t>(k) + 1]));
                for (Index o = 0; o < obstacles.size(); ++o)
                    if (obstacles[o].contains(c)) {
                        label[piece(i, j, k)] = o;
                        break;
                    }
            }
    // Greedy boxes of one label, seeded from the largest pieces first (a room's pieces before the thin ones of a door
    // or a wall, which would otherwise run through the rooms beyond them): from the seed, grown both ways along x,
    // then y, then z while the slab added is of the seed's label and not taken.
    std::vector<Index> owner(pieces, -1);
    struct Run {
        int lo[3], hi[3]; // pieces lo .. hi - 1
        bool free;
    };
    std::vector<Run> runs;
    const auto width = [&](int a, int i) {
        return cuts[a][static_cast<std::size_t>(i) + 1] - cuts[a][static_cast<std::size_t>(i)];
    };
    std::vector<std::array<int, 3>> seeds;
    seeds.reserve(pieces);
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i)
                seeds.push_back({i, j, k});
    std::stable_sort(seeds.begin(), seeds.end(), [&](const std::array<int, 3>& u, const std::array<int, 3>& v) {
        return width(0, u[0]) * width(1, u[1]) * width(2, u[2]) > width(0, v[0]) * width(1, v[1]) * width(2, v[2]);
    });
    for (const std::array<int, 3>& seed : seeds) {
        if (owner[piece(seed[0], seed[1], seed[2])] >= 0) continue;
        const Index l = label[piece(seed[0], seed[1], seed[2])];
        int lo[3] = {seed[0], seed[1], seed[2]}, hi[3] = {seed[0] + 1, seed[1] + 1, seed[2] + 1};
        // The slab of the box [lo, hi) moved to [from, from + 1) on axis a: all of label l and free to take.
        const auto fits = [&](int a, int from) {
            int b0[3] = {lo[0], lo[1], lo[2]}, b1[3] = {hi[0], hi[1], hi[2]};
            b0[a] = from;
            b1[a] = from + 1;
            for (int z = b0[2]; z < b1[2]; ++z)
                for (int y = b0[1]; y < b1[1]; ++y)
                    for (int x = b0[0]; x < b1[0]; ++x)
                        if (owner[piece(x, y, z)] >= 0 || label[piece(x, y, z)] != l) return false;
            return true;
        };
        for (int a = 0; a < 3; ++a) {
            while (hi[a] < n[a] && fits(a, hi[a]))
                ++hi[a];
            while (lo[a] > 0 && fits(a, lo[a] - 1))
                --lo[a];
        }
        const auto id = static_cast<Index>(runs.size());
        for (int z = lo[2]; z < hi[2]; ++z)
            for (int y = lo[1]; y < hi[1]; ++y)
                for (int x = lo[0]; x < hi[0]; ++x)
                    owner[piece(x, y, z)] = id;
        runs.push_back({{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}, l < 0});
    }
    CellLayout layout;
    Index free_count = 0, solid_count = 0;
    for (const Run& r : runs) {
        PortalCell c;
        c.name = r.free ? "free" + std::to_string(free_count++) : "solid" + std::to_string(solid_count++);
        for (int a = 0; a < 3; ++a) {
            c.lo[a] = cuts[a][static_cast<std::size_t>(r.lo[a])];
            c.hi[a] = cuts[a][static_cast<std::size_t>(r.hi[a])];
        }
        layout.cells.push_back(c);
    }
    // Portals: the whole face two free boxes share (both sides free), found from the pieces' faces.
    std::set<std::tuple<Index, Index, int>> shared;
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) {
                const Index u = owner[piece(i, j, k)];
                if (!runs[static_cast<std::size_t>(u)].free) continue;
                const int at[3] = {i, j, k};
                for (int a = 0; a < 3; ++a) {
                    if (at[a] + 1 >= n[a]) continue;
                    int nb[3] = {i, j, k};
                    ++nb[a];
                    const Index w = owner[piece(nb[0], nb[1], nb[2])];
                    if (w != u && runs[static_cast<std::size_t>(w)].free)
                        shared.emplace(std::min(u, w), std::max(u, w), a);
                }
            }
    for (const auto& [u, w, a] : shared) {
        const PortalCell& cu = layout.cells[static_cast<std::size_t>(u)];
        const PortalCell& cw = layout.cells[static_cast<std::size_t>(w)];
        Portal p;
        p.a = u;
        p.b = w;
        for (int b = 0; b < 3; ++b) {
            p.lo[b] = std::max(cu.lo[b], cw.lo[b]);
            p.hi[b] = std::min(cu.hi[b], cw.hi[b]);
        }
        layout.portals.push_back(p);
    }
    check_cell_layout(layout);
    return layout;
}

class CellWallsImpl {
  public:
    const ObstacleSet* obstacles = nullptr;
    std::vector<detail::Box> cells;
    detail::CellLocator locator;
    std::vector<std::vector<Index>> walls; // per cell, the outside last
};

CellWalls::CellWalls(const CellLayout& layout, const ObstacleSet& obstacles) : m_impl(std::make_unique<CellWallsImpl>())
{
    check_cell_layout(layout);
    CellWallsImpl& w = *m_impl;
    w.obstacles = &obstacles;
    for (const PortalCell& c : layout.cells) {
        detail::Box b{};
        std::copy(c.lo, c.lo + 3, b.lo);
        std::copy(c.hi, c.hi + 3, b.hi);
        w.cells.push_back(b);
    }
    w.locator.build(w.cells);
    w.walls.resize(w.cells.size() + 1);
    std::vector<Index> met;
    for (Index o = 0; o < obstacles.size(); ++o) {
        const detail::Box ob = obstacle_box(obstacles[o]);
        w.locator.overlapping(w.cells, ob, met);
        bool within_one = false;
        for (Index c : met) {
            w.walls[static_cast<std::size_t>(c)].push_back(o);
            const detail::Box& cb = w.cells[static_cast<std::size_t>(c)];
            within_one = within_one || (detail::in_box(ob.lo, cb.lo, cb.hi) && detail::in_box(ob.hi, cb.lo, cb.hi));
        }
        // An obstacle within one closed cell has no point outside every cell.
        if (!within_one) w.walls.back().push_back(o);
    }
}

CellWalls::~CellWalls() = default;
CellWalls::CellWalls(CellWalls&&) noexcept = default;
CellWalls& CellWalls::operator=(CellWalls&&) noexcept = default;

const std::vector<Index>& CellWalls::walls(Index cell) const
{
    return m_impl->walls.at(static_cast<std::size_t>(cell));
}

std::vector<ObstacleContact> CellWalls::query(const PositionsRef& positions, WallStats* stats) const
{
    const CellWallsImpl& w = *m_impl;
    WallStats st;
    std::vector<ObstacleContact> out;
    const auto outside = static_cast<Index>(w.cells.size());
    for (Eigen::Index i = 0; i < positions.rows(); ++i) {
        const Eigen::Vector3d p = positions.row(i).transpose();
        if (!p.allFinite()) continue; // never inside anything
        ++st.vertices;
        Index cell = w.locator.locate(w.cells, p.data());
        if (cell < 0) {
            cell = outside;
            ++st.outside;
        }
        for (Index o : w.walls[static_cast<std::size_t>(cell)]) {
            ++st.tests;
            const Bsp& b = (*w.obstacles)[o];
            if ((p.array() < b.box_lo().array()).any() || (p.array() > b.box_hi().array()).any()) continue;
            const BspHit hit = b.query(p);
            if (!hit.inside) continue;
            out.push_back(
                {static_cast<Index>(i), o, hit.depth, {hit.direction.x(), hit.direction.y(), hit.direction.z()}});
        }
    }
    st.all = st.vertices * w.obstacles->size();
    if (stats) *stats = st;
    return out;
}

} // namespace tethash
