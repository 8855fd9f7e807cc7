// Edge-face contacts at one instant (include/tethash/edge_contacts.hpp): the boundary, the grid of boxes over its
// triangles, each boundary edge's box queried in it, the object rules, the exact crossing test; per-thread lists
// merged and sorted.
#include "tethash/edge_contacts.hpp"

#include "../hash/box_grid.hpp"
#include "../hash/detect_checks.hpp"
#include "../hash/hash_grid.hpp"
#include "../team.hpp"
#include "boundary_edges.hpp"
#include "tethash/predicates.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace tethash {

EdgeFaceCrossing edge_face_crossing(const double* p, const double* q, const double* a, const double* b, const double* c)
{
    EdgeFaceCrossing r;
    const predicates::Orientation op = predicates::orient3d(a, b, c, p);
    const predicates::Orientation oq = predicates::orient3d(a, b, c, q);
    // Both ends strictly on opposite sides of the plane (a zero-area triangle gives zeros: never crossed).
    if (op.sign == 0 || oq.sign == 0 || op.sign == oq.sign) return r;
    // The line pq meets the closed triangle: the three edge orientations never of opposite strict signs. Each is, up
    // to a common factor, the barycentric coordinate of the crossing point at the opposite corner.
    const predicates::Orientation w[3] = {predicates::orient3d(p, q, b, c), predicates::orient3d(p, q, c, a),
                                          predicates::orient3d(p, q, a, b)};
    const bool positive = w[0].sign > 0 || w[1].sign > 0 || w[2].sign > 0;
    const bool negative = w[0].sign < 0 || w[1].sign < 0 || w[2].sign < 0;
    if (positive && negative) return r;
    r.crosses = true;
    // The values carry the exact signs (predicates.hpp), so their magnitudes give nonnegative coordinates; zeros
    // are exact.
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
        r.face_bary[k] = w[k].sign == 0 ? 0.0 : std::abs(w[k].value);
        sum += r.face_bary[k];
    }
    if (sum > 0) {
        for (double& v : r.face_bary)
            v /= sum;
    } else { // every value underflowed: the sign says which coordinates are nonzero
        const int nonzero = (w[0].sign != 0) + (w[1].sign != 0) + (w[2].sign != 0);
        for (int k = 0; k < 3; ++k)
            r.face_bary[k] = w[k].sign == 0 ? 0.0 : 1.0 / nonzero;
    }
    const double dp = std::abs(op.value), dq = std::abs(oq.value);
    r.edge_t = dp + dq > 0 ? dp / (dp + dq) : 0.5;
    r.inner_end = op.sign < 0 ? 0 : 1;
    const Eigen::Vector3d ea(a[0], a[1], a[2]), eb(b[0], b[1], b[2]), ec(c[0], c[1], c[2]);
    const Eigen::Vector3d n = (eb - ea).cross(ec - ea).normalized();
    for (int k = 0; k < 3; ++k)
        r.normal[k] = n[k];
    return r;
}

namespace {

using Vec3 = Eigen::Vector3d;
struct Box {
    double lo[3], hi[3];
};

/// The broad phase: the boundary triangles' boxes in the core's grid of boxes (box_grid.hpp), the table depending on
/// the input only. An edge queries its box and meets each triangle once, then tests the double boxes exactly. A
/// hashed grid replaced the core's box tree (triangle_bvh.hpp), whose node boxes overlap on overlapping bodies
/// (docs/ccd.md has the figures).
class FaceGrid {
  public:
    /// Cell size: the mean boundary edge length, doubled while the triangles would cover more than 64 cells each on
    /// average (a few huge triangles), and at least 2^-20 of the extent.
    void build(const PositionsRef& x, const Triangles& faces, const Edges& edges)
    {
        const auto nf = static_cast<std::size_t>(faces.rows());
        Vec3 origin = Vec3::Constant(std::numeric_limits<double>::infinity());
        Vec3 top = -origin;
        double length = 0;
        for (Eigen::Index f = 0; f < faces.rows(); ++f)
            for (int k = 0; k < 3; ++k) {
                const Vec3 p = x.row(faces(f, k)).transpose();
                origin = origin.cwiseMin(p);
                top = top.cwiseMax(p);
            }
        for (Eigen::Index e = 0; e < edges.rows(); ++e)
            length += (x.row(edges(e, 0)) - x.row(edges(e, 1))).norm();
        m_box.resize(nf);
        if (nf == 0) return;
        const double extent = (top - origin).maxCoeff();
        double cell = edges.rows() > 0 ? length / static_cast<double>(edges.rows()) : 0;
        cell = std::max(cell, std::ldexp(extent, -20));
        if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
        for (std::size_t f = 0; f < nf; ++f) {
            const auto fi = static_cast<Eigen::Index>(f);
            for (int a = 0; a < 3; ++a) {
                const double c0 = x(faces(fi, 0), a), c1 = x(faces(fi, 1), a), c2 = x(faces(fi, 2), a);
                m_box[f].lo[a] = std::min({c0, c1, c2});
                m_box[f].hi[a] = std::max({c0, c1, c2});
            }
        }
        std::int64_t total = 0;
        for (;;) {
            const double inv = 1 / cell;
            total = 0;
            for (const Box& b : m_box) {
                std::int64_t cells = 1;
                for (int a = 0; a < 3; ++a)
                    cells *= detail::BoxGrid::cell_of(b.hi[a], inv) - detail::BoxGrid::cell_of(b.lo[a], inv) + 1;
                total += cells;
            }
            if (total <= 64 * static_cast<std::int64_t>(nf)) break;
            cell *= 2;
        }
        const std::int64_t buckets = std::min(next_power_of_two(std::max<std::int64_t>(2 * total, 1)), max_table_size);
        m_grid.build(cell, static_cast<std::size_t>(buckets), nf, [&](std::int32_t i, double lo[3], double hi[3]) {
            const Box& b = m_box[static_cast<std::size_t>(i)];
            std::copy(b.lo, b.lo + 3, lo);
            std::copy(b.hi, b.hi + 3, hi);
        });
    }

    /// Calls visit(f) once for every triangle whose box meets the box lo..hi. `stamp`, `tag` and `hits` as
    /// BoxGrid::query's.
    template <class Visit>
    void for_box(const Vec3& lo, const Vec3& hi, std::int32_t* stamp, std::int32_t tag, std::vector<std::int32_t>& hits,
                 Visit&& visit) const
    {
        m_grid.query(lo.data(), hi.data(), stamp, tag, hits, false, [&](std::int32_t f) {
            const Box& b = m_box[static_cast<std::size_t>(f)];
            if ((lo[0] > b.hi[0]) | (lo[1] > b.hi[1]) | (lo[2] > b.hi[2]) | (hi[0] < b.lo[0]) | (hi[1] < b.lo[1]) |
                (hi[2] < b.lo[2]))
                return;
            visit(static_cast<Index>(f));
        });
    }

  private:
    std::vector<Box> m_box; ///< per face
    detail::BoxGrid m_grid;
};

} // namespace

void EdgeFaceDetector::set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                                    std::span<const Index> tet_object, std::span<const ObjectOptions> objects)
{
    detail::check_topology(tets, num_vertices, vertex_object, tet_object);
    const detail::ObjectFlags flags = detail::object_flags(vertex_object, tet_object, objects);
    m_num_vertices = num_vertices;
    m_self = flags.self_collision;
    m_static = flags.is_static;
    auto vobj = [&](Index v) { return vertex_object.empty() ? Index(0) : vertex_object[static_cast<std::size_t>(v)]; };
    m_result = EdgeFaceResult{};
    m_result.faces = boundary_faces(tets);
    m_result.edges = detail::edges_of_faces(m_result.faces);
    m_edge_object.resize(static_cast<std::size_t>(m_result.edges.rows()));
    for (Eigen::Index e = 0; e < m_result.edges.rows(); ++e)
        m_edge_object[static_cast<std::size_t>(e)] = vobj(m_result.edges(e, 0));
    m_face_object.resize(static_cast<std::size_t>(m_result.faces.rows()));
    for (Eigen::Index f = 0; f < m_result.faces.rows(); ++f)
        m_face_object[static_cast<std::size_t>(f)] = vobj(m_result.faces(f, 0));
    const bool any_self = std::any_of(m_self.begin(), m_self.end(), [](unsigned char s) { return s != 0; });
    Adjacency adj = any_self ? vertex_adjacency(tets, num_vertices) : Adjacency{};
    m_offsets = std::move(adj.offsets);
    m_neighbours = std::move(adj.neighbours);
}

const EdgeFaceResult& EdgeFaceDetector::find(const PositionsRef& positions, int threads)
{
    const Index n = m_num_vertices;
    detail::check_positions(positions, n);
    check_threads(threads, "EdgeFaceDetector::find: threads");
    const Triangles& faces = m_result.faces;
    const Edges& edges = m_result.edges;
    // True when some vertex of the edge and some vertex of the triangle are the same or are joined by a mesh edge
    // (share a tet): such a pair is never a self contact.
    auto near_in_mesh = [&](const Index* e, const Index* f) {
        for (int i = 0; i < 2; ++i) {
            const auto begin = m_neighbours.begin() + m_offsets[static_cast<std::size_t>(e[i])];
            const auto end = m_neighbours.begin() + m_offsets[static_cast<std::size_t>(e[i]) + 1];
            for (int k = 0; k < 3; ++k)
                if (e[i] == f[k] || std::binary_search(begin, end, f[k])) return true;
        }
        return false;
    };

    auto point = [&](Index v) { return Vec3(positions(v, 0), positions(v, 1), positions(v, 2)); };
    FaceGrid grid;
    grid.build(positions, faces, edges);

#ifdef TETHASH_HAVE_OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#endif
    threads = std::max(threads, 1);
    std::vector<std::vector<EdgeFaceContact>> found(static_cast<std::size_t>(threads));
    std::vector<std::int64_t> candidates(static_cast<std::size_t>(threads), 0);
    const std::int64_t ne = edges.rows();
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(threads) if (threads > 1)
#endif
    {
        const int rank = detail::team_rank(), size = detail::team_size();
        auto& out = found[static_cast<std::size_t>(rank)];
        std::int64_t& count = candidates[static_cast<std::size_t>(rank)];
        std::int64_t begin = 0, end = 0;
        detail::team_split(ne, rank, size, begin, end);
        std::vector<std::int32_t> stamp(static_cast<std::size_t>(faces.rows()), -1), hits;
        for (std::int64_t e = begin; e < end; ++e) {
            const Index ev[2] = {edges(e, 0), edges(e, 1)};
            const Index eo = m_edge_object[static_cast<std::size_t>(e)];
            const bool e_static = m_static[static_cast<std::size_t>(eo)] != 0;
            const Vec3 p = point(ev[0]), q = point(ev[1]);
            const Vec3 lo = p.cwiseMin(q), hi = p.cwiseMax(q);
            grid.for_box(lo, hi, stamp.data(), static_cast<std::int32_t>(e), hits, [&](Index f) {
                const Index fv[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
                const Index fo = m_face_object[static_cast<std::size_t>(f)];
                if (e_static && m_static[static_cast<std::size_t>(fo)]) return;
                if (eo == fo) {
                    if (!m_self[static_cast<std::size_t>(eo)] || near_in_mesh(ev, fv)) return;
                } else if (ev[0] == fv[0] || ev[0] == fv[1] || ev[0] == fv[2] || ev[1] == fv[0] || ev[1] == fv[1] ||
                           ev[1] == fv[2]) {
                    return;
                }
                ++count;
                const Vec3 a = point(fv[0]), b = point(fv[1]), c = point(fv[2]);
                const EdgeFaceCrossing x = edge_face_crossing(p.data(), q.data(), a.data(), b.data(), c.data());
                if (!x.crosses) return;
                EdgeFaceContact ct;
                ct.edge = static_cast<Index>(e);
                ct.face = f;
                ct.edge_vertices[0] = ev[0];
                ct.edge_vertices[1] = ev[1];
                for (int k = 0; k < 3; ++k) {
                    ct.face_vertices[k] = fv[k];
                    ct.face_bary[k] = x.face_bary[k];
                    ct.normal[k] = x.normal[k];
                }
                ct.edge_object = eo;
                ct.face_object = fo;
                ct.edge_t = x.edge_t;
                ct.inner_end = x.inner_end;
                out.push_back(ct);
            });
        }
    }
    m_result.contacts.clear();
    m_result.candidates = 0;
    for (int r = 0; r < threads; ++r) {
        const auto& part = found[static_cast<std::size_t>(r)];
        m_result.contacts.insert(m_result.contacts.end(), part.begin(), part.end());
        m_result.candidates += candidates[static_cast<std::size_t>(r)];
    }
    std::sort(m_result.contacts.begin(), m_result.contacts.end(),
              [](const EdgeFaceContact& x, const EdgeFaceContact& y) {
                  return x.edge < y.edge || (x.edge == y.edge && x.face < y.face);
              });
    return m_result;
}

EdgeFaceResult find_edge_face_contacts(const TetsRef& tets, const PositionsRef& positions,
                                       std::span<const Index> vertex_object, std::span<const Index> tet_object,
                                       std::span<const ObjectOptions> objects, int threads)
{
    EdgeFaceDetector detector;
    detector.set_topology(tets, static_cast<Index>(positions.rows()), vertex_object, tet_object, objects);
    return detector.find(positions, threads);
}

} // namespace tethash
