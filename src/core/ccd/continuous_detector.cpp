// Continuous detection kept between calls (include/tethash/continuous.hpp, ContinuousDetector): the boundary found
// once; per call the swept boxes of the boundary vertices, faces and edges, the faces' and edges' boxes in the core's
// grid of boxes (box_grid.hpp), each vertex and edge querying it, the exact double box test, the narrow phase of
// ccd.hpp, per-thread lists merged and sorted.
#include "tethash/continuous.hpp"

#include "../hash/box_grid.hpp"
#include "../hash/hash_grid.hpp"
#include "../hash/table_size.hpp"
#include "../team.hpp"
#include "boundary_edges.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

namespace tethash::ccd {
namespace {

using Vec3 = Eigen::Vector3d;

struct Box {
    double lo[3], hi[3];
};

bool overlap(const Box& a, const Box& b)
{
    return !((a.lo[0] > b.hi[0]) | (a.lo[1] > b.hi[1]) | (a.lo[2] > b.hi[2]) | (b.lo[0] > a.hi[0]) |
             (b.lo[1] > a.hi[1]) | (b.lo[2] > a.hi[2]));
}

void grow(Box& b, const Box& c)
{
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::min(b.lo[k], c.lo[k]);
        b.hi[k] = std::max(b.hi[k], c.hi[k]);
    }
}

/// The grids' cell size in mean boundary edges (before the doubling of a fast step).
constexpr double cell_edges = 3;

/// The threads a parallel loop asked for `threads` (0: all) runs on.
int thread_slots(int threads)
{
#ifdef TETHASH_HAVE_OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#endif
    return std::max(threads, 1);
}

/// Cells of the boxes `boxes[i]` (i in `ids`) in a grid of cell size 1 / inv.
std::int64_t cells_of(const std::vector<Box>& boxes, const std::vector<std::int32_t>& ids, double inv)
{
    std::int64_t total = 0;
    for (const std::int32_t i : ids) {
        const Box& b = boxes[static_cast<std::size_t>(i)];
        std::int64_t cells = 1;
        for (int a = 0; a < 3; ++a)
            cells *= detail::BoxGrid::cell_of(b.hi[a], inv) - detail::BoxGrid::cell_of(b.lo[a], inv) + 1;
        total += cells;
    }
    return total;
}

/// The boxes `boxes[i]` (i in `ids`, in order) into `grid` of cell size `cell`; `total`: their cells (cells_of).
void fill_grid(detail::BoxGrid& grid, double cell, const std::vector<Box>& boxes, const std::vector<std::int32_t>& ids,
               std::int64_t total)
{
    const std::int64_t buckets = std::min(next_power_of_two(std::max<std::int64_t>(2 * total, 1)), max_table_size);
    grid.build(cell, static_cast<std::size_t>(buckets), ids.size(), [&](std::int32_t k, double lo[3], double hi[3]) {
        const Box& b = boxes[static_cast<std::size_t>(ids[static_cast<std::size_t>(k)])];
        std::copy(b.lo, b.lo + 3, lo);
        std::copy(b.hi, b.hi + 3, hi);
    });
}

/// Which coarse cells (cell size `coarse`) some box of a grid meets, as bits hashed from the cells: a query box none
/// of whose coarse cells is marked meets no box of the grid and skips its query. (A filter: hashed bits may collide,
/// never miss.)
class Occupancy {
  public:
    void clear(double coarse)
    {
        m_inv = 1 / coarse;
        m_bits.assign(words, 0);
        m_everywhere = false;
        m_bound = Box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    }
    void mark(const Box& b)
    {
        grow(m_bound, b);
        std::int64_t c0[3], c1[3];
        if (!cells(b, c0, c1)) {
            m_everywhere = true; // a box over very many coarse cells: every query goes on to the grid
            return;
        }
        for (std::int64_t x = c0[0]; x <= c1[0]; ++x)
            for (std::int64_t y = c0[1]; y <= c1[1]; ++y)
                for (std::int64_t z = c0[2]; z <= c1[2]; ++z) {
                    const std::uint64_t h = bit(x, y, z);
                    m_bits[h >> 6] |= std::uint64_t{1} << (h & 63);
                }
    }
    bool meets(const Box& b) const
    {
        // First the box of every marked box: where few primitives move, in one region, most queries end here.
        if (!overlap(b, m_bound)) return false;
        std::int64_t c0[3], c1[3];
        if (m_everywhere || !cells(b, c0, c1)) return true;
        for (std::int64_t x = c0[0]; x <= c1[0]; ++x)
            for (std::int64_t y = c0[1]; y <= c1[1]; ++y)
                for (std::int64_t z = c0[2]; z <= c1[2]; ++z) {
                    const std::uint64_t h = bit(x, y, z);
                    if (m_bits[h >> 6] & (std::uint64_t{1} << (h & 63))) return true;
                }
        return false;
    }

  private:
    static constexpr std::size_t words = 1024; // 65,536 bits
    /// The coarse cells of b; false when they are more than 512.
    bool cells(const Box& b, std::int64_t c0[3], std::int64_t c1[3]) const
    {
        double count = 1;
        for (int k = 0; k < 3; ++k) {
            const double lo = b.lo[k] * m_inv, hi = b.hi[k] * m_inv;
            if (!(hi - lo < 512)) return false;
            count *= hi - lo + 2;
            c0[k] = detail::BoxGrid::cell_of(b.lo[k], m_inv);
            c1[k] = detail::BoxGrid::cell_of(b.hi[k], m_inv);
        }
        return count <= 512;
    }
    static std::uint64_t bit(std::int64_t x, std::int64_t y, std::int64_t z)
    {
        return teschner_hash(static_cast<std::int32_t>(x), static_cast<std::int32_t>(y), static_cast<std::int32_t>(z)) &
               (64 * words - 1);
    }
    double m_inv = 1;
    std::vector<std::uint64_t> m_bits;
    bool m_everywhere = false;
    Box m_bound{}; ///< the box of the marked boxes
};

} // namespace

struct ContinuousDetector::State {
    Index num_vertices = 0;
    ContinuousResult result;     ///< faces and edges kept; contacts and counts per call
    std::vector<Index> vertices; ///< the boundary vertices, increasing
    std::vector<Box> vertex_box, face_box, edge_box;
    detail::BoxGrid face_grid, edge_grid, vertex_grid;
    std::vector<std::int32_t> face_ids, edge_ids, vertex_ids; ///< per grid box: its face, edge, boundary vertex
    std::vector<std::int32_t> edge_slot;                      ///< per edge: its box in edge_grid, or −1
    Occupancy face_cells, edge_cells, vertex_cells;           ///< the grids' coarse cells (with a mask)
    std::vector<unsigned char> face_moving, edge_moving;
    /// set_locality: rest positions, a group per vertex, a squared reach per group (empty: no rule).
    Positions rest;
    std::vector<Index> group;
    std::vector<double> reach_sq;
    struct Scratch {
        std::vector<std::int32_t> stamp, hits;
        std::vector<ContinuousContact> found;
        std::int64_t vf = 0, ee = 0, met = 0;
    };
    std::vector<Scratch> scratch;
};

ContinuousDetector::ContinuousDetector() : m_state(std::make_unique<State>()) {}
ContinuousDetector::~ContinuousDetector() = default;
ContinuousDetector::ContinuousDetector(ContinuousDetector&&) noexcept = default;
ContinuousDetector& ContinuousDetector::operator=(ContinuousDetector&&) noexcept = default;

void ContinuousDetector::set_topology(const TetsRef& tets, Index num_vertices)
{
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
        for (int c = 0; c < 4; ++c)
            if (tets(t, c) < 0 || tets(t, c) >= num_vertices)
                throw Error("ContinuousDetector::set_topology: tet " + std::to_string(t) + " names vertex " +
                            std::to_string(tets(t, c)) + ", outside [0, " + std::to_string(num_vertices) + ")");
    State& s = *m_state;
    s.num_vertices = num_vertices;
    s.result = ContinuousResult{};
    s.rest.resize(0, 3);
    s.group.clear();
    s.reach_sq.clear();
    s.result.faces = boundary_faces(tets);
    s.result.edges = detail::edges_of_faces(s.result.faces);
    s.vertices.assign(s.result.faces.data(), s.result.faces.data() + s.result.faces.size());
    std::sort(s.vertices.begin(), s.vertices.end());
    s.vertices.erase(std::unique(s.vertices.begin(), s.vertices.end()), s.vertices.end());
    s.vertex_box.assign(static_cast<std::size_t>(num_vertices), Box{});
    s.face_box.resize(static_cast<std::size_t>(s.result.faces.rows()));
    s.edge_box.resize(static_cast<std::size_t>(s.result.edges.rows()));
}

void ContinuousDetector::set_locality(const PositionsRef& rest, std::span<const Index> vertex_group,
                                      std::span<const double> reach_sq)
{
    State& s = *m_state;
    const std::string where = "ContinuousDetector::set_locality: ";
    if (rest.rows() != s.num_vertices || static_cast<Index>(vertex_group.size()) != s.num_vertices)
        throw Error(where + "the rest positions have " + std::to_string(rest.rows()) + " rows and the groups " +
                    std::to_string(vertex_group.size()) + " entries, the topology " + std::to_string(s.num_vertices) +
                    " vertices");
    for (std::size_t g = 0; g < reach_sq.size(); ++g)
        if (!(reach_sq[g] >= 0 && reach_sq[g] < std::numeric_limits<double>::infinity()))
            throw Error(where + "the squared reach of group " + std::to_string(g) + " is negative or not finite");
    for (Index v = 0; v < s.num_vertices; ++v) {
        const Index g = vertex_group[static_cast<std::size_t>(v)];
        if (g < 0 || static_cast<std::size_t>(g) >= reach_sq.size())
            throw Error(where + "vertex " + std::to_string(v) + " is in group " + std::to_string(g) + ", outside [0, " +
                        std::to_string(reach_sq.size()) + ")");
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(rest(v, k)))
                throw Error(where + "rest coordinate " + std::to_string(k) + " of vertex " + std::to_string(v) +
                            " is not finite");
    }
    s.rest = rest;
    s.group.assign(vertex_group.begin(), vertex_group.end());
    s.reach_sq.assign(reach_sq.begin(), reach_sq.end());
}

const Triangles& ContinuousDetector::faces() const
{
    return m_state->result.faces;
}
const Edges& ContinuousDetector::edges() const
{
    return m_state->result.edges;
}

const ContinuousResult& ContinuousDetector::detect(const PositionsRef& x0, const PositionsRef& x1,
                                                   const ContinuousParams& params,
                                                   std::span<const unsigned char> moving, const PairFilter& keep)
{
    State& s = *m_state;
    const Index n = s.num_vertices;
    for (const PositionsRef* x : {&x0, &x1})
        if (x->rows() != n)
            throw Error(std::string("ContinuousDetector::detect: the ") + (x == &x0 ? "start" : "end") +
                        " positions have " + std::to_string(x->rows()) + " rows, the topology " + std::to_string(n) +
                        " vertices");
    if (!moving.empty() && static_cast<Index>(moving.size()) != n)
        throw Error("ContinuousDetector::detect: `moving` has " + std::to_string(moving.size()) +
                    " entries, the topology " + std::to_string(n) + " vertices");
    for (const PositionsRef* x : {&x0, &x1})
        for (Eigen::Index i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k)
                if (!(std::abs((*x)(i, k)) <= 1e50))
                    throw Error(std::string("ContinuousDetector::detect: coordinate ") + std::to_string(k) +
                                " of vertex " + std::to_string(i) + " at " + (x == &x0 ? "the start" : "the end") +
                                " is not finite or above 1e50 in magnitude");
    if (!(params.query.tolerance > 0 && params.query.tolerance < 1e300) || params.query.max_iterations < 1)
        throw Error("ContinuousDetector::detect: the tolerance must be positive and finite and max_iterations at "
                    "least 1");

    ContinuousResult& result = s.result;
    result.contacts.clear();
    result.vertex_face_candidates = result.edge_edge_candidates = result.broad_phase_pairs = 0;
    const Triangles& faces = result.faces;
    const Edges& edges = result.edges;
    const auto nf = static_cast<std::size_t>(faces.rows()), ne = static_cast<std::size_t>(edges.rows());
    if (nf == 0) return result;
    const bool masked = !moving.empty();
    auto is_moving = [&](Index v) { return !masked || moving[static_cast<std::size_t>(v)] != 0; };

    // Swept boxes: a vertex's over its two positions, a face's and an edge's over their corners'.
    double length = 0;
    for (const Index v : s.vertices) {
        Box& b = s.vertex_box[static_cast<std::size_t>(v)];
        for (int k = 0; k < 3; ++k) {
            b.lo[k] = std::min(x0(v, k), x1(v, k));
            b.hi[k] = std::max(x0(v, k), x1(v, k));
        }
    }
    s.face_moving.assign(nf, 0);
    for (std::size_t f = 0; f < nf; ++f) {
        const auto fi = static_cast<Eigen::Index>(f);
        Box b = s.vertex_box[static_cast<std::size_t>(faces(fi, 0))];
        grow(b, s.vertex_box[static_cast<std::size_t>(faces(fi, 1))]);
        grow(b, s.vertex_box[static_cast<std::size_t>(faces(fi, 2))]);
        s.face_box[f] = b;
        s.face_moving[f] = is_moving(faces(fi, 0)) || is_moving(faces(fi, 1)) || is_moving(faces(fi, 2));
    }
    s.edge_moving.assign(ne, 0);
    for (std::size_t e = 0; e < ne; ++e) {
        const auto ei = static_cast<Eigen::Index>(e);
        Box b = s.vertex_box[static_cast<std::size_t>(edges(ei, 0))];
        grow(b, s.vertex_box[static_cast<std::size_t>(edges(ei, 1))]);
        s.edge_box[e] = b;
        s.edge_moving[e] = is_moving(edges(ei, 0)) || is_moving(edges(ei, 1));
        length += (x0.row(edges(ei, 0)) - x0.row(edges(ei, 1))).norm();
    }
    // Cell size: three mean boundary edges at the start (every primitive queries the grids), doubled while the swept
    // boxes would cover more than 64 cells each on average (a fast step), and at least 2^-20 of the extent. Cells of
    // one edge put a swept box in 4-8 cells, and a query met most of its boxes in several of them (a stamp each): on
    // the hand's sweeps at 1/60 cells of three edges took the sweep from 11.8 to 7.6 ms of CPU time, at 1/240 from
    // 3.0 to 2.6 ms (four edges: the same within 2 %).
    Box all = s.face_box[0];
    for (const Box& b : s.face_box)
        grow(all, b);
    double extent = 0;
    for (int k = 0; k < 3; ++k)
        extent = std::max(extent, all.hi[k] - all.lo[k]);
    double cell = ne > 0 ? cell_edges * length / static_cast<double>(ne) : 0;
    cell = std::max(cell, std::ldexp(extent, -20));
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
    // The grids hold the moving primitives (every one without a mask) and every primitive queries them: a pair is a
    // candidate when one of its primitives moves. A few moving primitives make small grids, and the others' queries
    // mostly end at the coarse cells below.
    s.face_ids.clear();
    for (std::size_t f = 0; f < nf; ++f)
        if (s.face_moving[f]) s.face_ids.push_back(static_cast<std::int32_t>(f));
    s.edge_ids.clear();
    s.edge_slot.assign(ne, -1);
    for (std::size_t e = 0; e < ne; ++e)
        if (s.edge_moving[e]) {
            s.edge_slot[e] = static_cast<std::int32_t>(s.edge_ids.size());
            s.edge_ids.push_back(static_cast<std::int32_t>(e));
        }
    std::int64_t face_cells = 0, edge_cells = 0;
    for (;;) {
        face_cells = cells_of(s.face_box, s.face_ids, 1 / cell);
        edge_cells = cells_of(s.edge_box, s.edge_ids, 1 / cell);
        if (face_cells + edge_cells <= 64 * static_cast<std::int64_t>(s.face_ids.size() + s.edge_ids.size())) break;
        cell *= 2;
    }
    fill_grid(s.face_grid, cell, s.face_box, s.face_ids, face_cells);
    fill_grid(s.edge_grid, cell, s.edge_box, s.edge_ids, edge_cells);
    // With a mask, the faces that do not move also meet the moving vertices.
    s.vertex_ids.clear();
    if (masked) {
        for (const Index v : s.vertices)
            if (is_moving(v)) s.vertex_ids.push_back(static_cast<std::int32_t>(v));
        fill_grid(s.vertex_grid, cell, s.vertex_box, s.vertex_ids, cells_of(s.vertex_box, s.vertex_ids, 1 / cell));
        // Coarse cells of four grid cells: most queries of a few moving primitives end here.
        s.face_cells.clear(4 * cell);
        s.edge_cells.clear(4 * cell);
        s.vertex_cells.clear(4 * cell);
        for (const std::int32_t f : s.face_ids)
            s.face_cells.mark(s.face_box[static_cast<std::size_t>(f)]);
        for (const std::int32_t e : s.edge_ids)
            s.edge_cells.mark(s.edge_box[static_cast<std::size_t>(e)]);
        for (const std::int32_t v : s.vertex_ids)
            s.vertex_cells.mark(s.vertex_box[static_cast<std::size_t>(v)]);
    }

    const int threads = thread_slots(params.threads);
    s.scratch.resize(std::max(s.scratch.size(), static_cast<std::size_t>(threads)));
    for (State::Scratch& w : s.scratch) { // a team smaller than asked leaves some unused
        w.found.clear();
        w.vf = w.ee = w.met = 0;
    }
    const auto nv = static_cast<std::int64_t>(s.vertices.size());
    const auto shares_face = [&](Index v, Index f) { return faces(f, 0) == v || faces(f, 1) == v || faces(f, 2) == v; };
    const auto shares_edge = [&](Index e, Index g) {
        return edges(e, 0) == edges(g, 0) || edges(e, 0) == edges(g, 1) || edges(e, 1) == edges(g, 0) ||
               edges(e, 1) == edges(g, 1);
    };
    auto row = [](const PositionsRef& x, Index v) { return Vec3(x(v, 0), x(v, 1), x(v, 2)); };
    // The locality rule (set_locality): the primitives' first vertices in one group, some two of their vertices
    // nearer than its reach at rest.
    const bool with_locality = !s.group.empty();
    const auto local = [&](const Index* a, int na, const Index* b, int nb) {
        const Index g = s.group[static_cast<std::size_t>(a[0])];
        if (g != s.group[static_cast<std::size_t>(b[0])]) return false;
        const double reach_sq = s.reach_sq[static_cast<std::size_t>(g)];
        for (int i = 0; i < na; ++i)
            for (int k = 0; k < nb; ++k)
                if ((s.rest.row(a[i]) - s.rest.row(b[k])).squaredNorm() < reach_sq) return true;
        return false;
    };
    const auto local_vertex_face = [&](Index v, Index f) {
        const Index fv[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
        return with_locality && local(&v, 1, fv, 3);
    };
    const auto local_edge_edge = [&](Index e, Index g) {
        const Index ev[2] = {edges(e, 0), edges(e, 1)}, gv[2] = {edges(g, 0), edges(g, 1)};
        return with_locality && local(ev, 2, gv, 2);
    };
    std::atomic<bool> met{false}; // params.first_only: some pair met
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(threads) if (threads > 1)
#endif
    {
        const int rank = detail::team_rank(), size = detail::team_size();
        State::Scratch& w = s.scratch[static_cast<std::size_t>(rank)];
        auto vertex_face = [&](Index v, Index f) {
            if (params.first_only && met.load(std::memory_order_relaxed)) return;
            if (keep && !keep(ContinuousKind::vertex_face, v, f)) return;
            ++w.vf;
            const CcdResult r = vertex_face_ccd(row(x0, v), row(x0, faces(f, 0)), row(x0, faces(f, 1)),
                                                row(x0, faces(f, 2)), row(x1, v), row(x1, faces(f, 0)),
                                                row(x1, faces(f, 1)), row(x1, faces(f, 2)), params.query);
            if (!r.hit) return;
            w.found.push_back({ContinuousKind::vertex_face, v, f, r.toi, r.outcome});
            met.store(true, std::memory_order_relaxed);
        };
        auto edge_edge = [&](Index e, Index g) {
            if (params.first_only && met.load(std::memory_order_relaxed)) return;
            if (keep && !keep(ContinuousKind::edge_edge, e, g)) return;
            ++w.ee;
            const CcdResult r = edge_edge_ccd(row(x0, edges(e, 0)), row(x0, edges(e, 1)), row(x0, edges(g, 0)),
                                              row(x0, edges(g, 1)), row(x1, edges(e, 0)), row(x1, edges(e, 1)),
                                              row(x1, edges(g, 0)), row(x1, edges(g, 1)), params.query);
            if (!r.hit) return;
            w.found.push_back({ContinuousKind::edge_edge, e, g, r.toi, r.outcome});
            met.store(true, std::memory_order_relaxed);
        };
        std::int64_t begin = 0, end = 0;
        // Every vertex against the moving faces.
        w.stamp.assign(std::max({s.face_ids.size(), s.edge_ids.size(), s.vertex_ids.size()}), -1);
        detail::team_split(nv, rank, size, begin, end);
        for (std::int64_t i = begin; i < end; ++i) {
            const Index v = s.vertices[static_cast<std::size_t>(i)];
            const Box& vb = s.vertex_box[static_cast<std::size_t>(v)];
            if (masked && !s.face_cells.meets(vb)) continue;
            s.face_grid.query(vb.lo, vb.hi, w.stamp.data(), static_cast<std::int32_t>(i), w.hits, false,
                              [&](std::int32_t k) {
                                  ++w.met;
                                  const Index f = s.face_ids[static_cast<std::size_t>(k)];
                                  if (shares_face(v, f) || local_vertex_face(v, f) ||
                                      !overlap(vb, s.face_box[static_cast<std::size_t>(f)]))
                                      return;
                                  vertex_face(v, f);
                              });
        }
        // The faces that do not move against the moving vertices.
        if (masked) {
            std::fill(w.stamp.begin(), w.stamp.end(), -1);
            detail::team_split(static_cast<std::int64_t>(nf), rank, size, begin, end);
            for (std::int64_t f = begin; f < end; ++f) {
                if (s.face_moving[static_cast<std::size_t>(f)]) continue;
                const Box& fb = s.face_box[static_cast<std::size_t>(f)];
                if (!s.vertex_cells.meets(fb)) continue;
                s.vertex_grid.query(
                    fb.lo, fb.hi, w.stamp.data(), static_cast<std::int32_t>(f), w.hits, false, [&](std::int32_t k) {
                        ++w.met;
                        const Index v = s.vertex_ids[static_cast<std::size_t>(k)];
                        if (shares_face(v, static_cast<Index>(f)) || local_vertex_face(v, static_cast<Index>(f)) ||
                            !overlap(fb, s.vertex_box[static_cast<std::size_t>(v)]))
                            return;
                        vertex_face(v, static_cast<Index>(f));
                    });
            }
        }
        // Every edge against the moving edges, each pair once: a moving edge queries only the grid's boxes above its
        // own (the edges' order), so neither the other half of a moving pair nor the edge itself is met.
        std::fill(w.stamp.begin(), w.stamp.end(), -1);
        detail::team_split(static_cast<std::int64_t>(ne), rank, size, begin, end);
        for (std::int64_t e = begin; e < end; ++e) {
            const std::int32_t slot = s.edge_slot[static_cast<std::size_t>(e)];
            const Box& eb = s.edge_box[static_cast<std::size_t>(e)];
            if (masked && slot < 0 && !s.edge_cells.meets(eb)) continue;
            s.edge_grid.query_above(
                slot, eb.lo, eb.hi, w.stamp.data(), static_cast<std::int32_t>(e), w.hits, false, [&](std::int32_t k) {
                    ++w.met;
                    const Index g = s.edge_ids[static_cast<std::size_t>(k)];
                    if (shares_edge(static_cast<Index>(e), g) || local_edge_edge(static_cast<Index>(e), g) ||
                        !overlap(eb, s.edge_box[static_cast<std::size_t>(g)]))
                        return;
                    if (g > e)
                        edge_edge(static_cast<Index>(e), g);
                    else
                        edge_edge(g, static_cast<Index>(e));
                });
        }
    }
    for (int r = 0; r < threads; ++r) {
        const State::Scratch& w = s.scratch[static_cast<std::size_t>(r)];
        result.contacts.insert(result.contacts.end(), w.found.begin(), w.found.end());
        result.vertex_face_candidates += w.vf;
        result.edge_edge_candidates += w.ee;
        result.broad_phase_pairs += w.met;
    }
    std::sort(result.contacts.begin(), result.contacts.end(),
              [](const ContinuousContact& p, const ContinuousContact& q) {
                  if (p.kind != q.kind) return p.kind < q.kind;
                  if (p.a != q.a) return p.a < q.a;
                  return p.b < q.b;
              });
    return result;
}

} // namespace tethash::ccd
