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
#include <string>

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
    /// Cell size: the mean boundary edge length, doubled while the triangles (grown by `grow` per side) would cover
    /// more than 64 cells each on average (a few huge triangles), and at least 2^-20 of the extent. The grid holds the
    /// boxes grown by `grow`; tight() keeps the triangles' own.
    void build(const PositionsRef& x, const Triangles& faces, const Edges& edges, double grow)
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
        m_tight.resize(nf);
        if (nf == 0) return;
        const double extent = (top - origin).maxCoeff();
        double cell = edges.rows() > 0 ? length / static_cast<double>(edges.rows()) : 0;
        cell = std::max(cell, std::ldexp(extent, -20));
        if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
        for (std::size_t f = 0; f < nf; ++f) {
            const auto fi = static_cast<Eigen::Index>(f);
            for (int a = 0; a < 3; ++a) {
                const double c0 = x(faces(fi, 0), a), c1 = x(faces(fi, 1), a), c2 = x(faces(fi, 2), a);
                m_tight[f].lo[a] = std::min({c0, c1, c2});
                m_tight[f].hi[a] = std::max({c0, c1, c2});
                m_box[f].lo[a] = m_tight[f].lo[a] - grow;
                m_box[f].hi[a] = m_tight[f].hi[a] + grow;
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

    /// Calls visit(f) once for every triangle whose grown box meets the box lo..hi. `stamp`, `tag` and `hits` as
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
    /// Triangle f's own box (not grown).
    const Box& tight(Index f) const { return m_tight[static_cast<std::size_t>(f)]; }

  private:
    std::vector<Box> m_box;   ///< per face, grown
    std::vector<Box> m_tight; ///< per face
    detail::BoxGrid m_grid;
};

bool boxes_meet(const Box& a, const Box& b)
{
    return !((a.lo[0] > b.hi[0]) | (a.lo[1] > b.hi[1]) | (a.lo[2] > b.hi[2]) | (a.hi[0] < b.lo[0]) |
             (a.hi[1] < b.lo[1]) | (a.hi[2] < b.lo[2]));
}

/// The contact of edge e (ends ev at p, q) and face f (corners fv), when they cross.
bool crossing_contact(Index e, const Index ev[2], const Vec3& p, const Vec3& q, Index f, const Index fv[3],
                      const PositionsRef& x, Index eo, Index fo, EdgeFaceContact& ct)
{
    const Vec3 a(x(fv[0], 0), x(fv[0], 1), x(fv[0], 2)), b(x(fv[1], 0), x(fv[1], 1), x(fv[1], 2)),
        c(x(fv[2], 0), x(fv[2], 1), x(fv[2], 2));
    const EdgeFaceCrossing r = edge_face_crossing(p.data(), q.data(), a.data(), b.data(), c.data());
    if (!r.crosses) return false;
    ct.edge = e;
    ct.face = f;
    ct.edge_vertices[0] = ev[0];
    ct.edge_vertices[1] = ev[1];
    for (int k = 0; k < 3; ++k) {
        ct.face_vertices[k] = fv[k];
        ct.face_bary[k] = r.face_bary[k];
        ct.normal[k] = r.normal[k];
    }
    ct.edge_object = eo;
    ct.face_object = fo;
    ct.edge_t = r.edge_t;
    ct.inner_end = r.inner_end;
    return true;
}

int team_threads(int threads)
{
#ifdef TETHASH_HAVE_OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#endif
    return std::max(threads, 1);
}

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
    m_boundary_vertices.assign(m_result.edges.data(), m_result.edges.data() + m_result.edges.size());
    std::sort(m_boundary_vertices.begin(), m_boundary_vertices.end());
    m_boundary_vertices.erase(std::unique(m_boundary_vertices.begin(), m_boundary_vertices.end()),
                              m_boundary_vertices.end());
    m_rest.clear();
    m_reach.clear();
    m_local_faces.clear();
    m_local_listed.clear();
    m_reference.clear();
    m_kept_edge.clear();
    m_kept_face.clear();
    m_kept_valid = false;
    m_paused = false;
    m_reuses = 0;
}

void EdgeFaceDetector::set_local_reach(const PositionsRef& rest, std::span<const double> reach)
{
    m_rest.clear();
    m_reach.clear();
    m_local_faces.clear();
    m_local_listed.clear();
    m_kept_valid = false;
    if (reach.empty()) return;
    detail::check_positions(rest, m_num_vertices);
    if (reach.size() < m_self.size())
        throw Error("EdgeFaceDetector::set_local_reach: " + std::to_string(reach.size()) + " reaches for " +
                    std::to_string(m_self.size()) + " objects");
    for (std::size_t o = 0; o < reach.size(); ++o)
        if (!(reach[o] >= 0) || !std::isfinite(reach[o]))
            throw Error("EdgeFaceDetector::set_local_reach: reach of object " + std::to_string(o) +
                        " must be a finite length >= 0, found " + std::to_string(reach[o]));
    m_reach.assign(reach.begin(), reach.end());
    // The rest spheres of the edges and faces: centroid, farthest vertex.
    const auto sphere = [&](const Index* v, int n) {
        Sphere sp{};
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k)
                sp.c[k] += rest(v[i], k) / n;
        for (int i = 0; i < n; ++i)
            sp.r = std::max(sp.r, std::sqrt((rest(v[i], 0) - sp.c[0]) * (rest(v[i], 0) - sp.c[0]) +
                                            (rest(v[i], 1) - sp.c[1]) * (rest(v[i], 1) - sp.c[1]) +
                                            (rest(v[i], 2) - sp.c[2]) * (rest(v[i], 2) - sp.c[2])));
        return sp;
    };
    m_edge_sphere.resize(static_cast<std::size_t>(m_result.edges.rows()));
    for (Index e = 0; e < m_result.edges.rows(); ++e) {
        const Index v[2] = {m_result.edges(e, 0), m_result.edges(e, 1)};
        m_edge_sphere[static_cast<std::size_t>(e)] = sphere(v, 2);
    }
    m_face_sphere.resize(static_cast<std::size_t>(m_result.faces.rows()));
    for (Index f = 0; f < m_result.faces.rows(); ++f) {
        const Index v[3] = {m_result.faces(f, 0), m_result.faces(f, 1), m_result.faces(f, 2)};
        m_face_sphere[static_cast<std::size_t>(f)] = sphere(v, 3);
    }
    m_local_faces.assign(static_cast<std::size_t>(m_result.edges.rows()), {});
    m_local_listed.assign(static_cast<std::size_t>(m_result.edges.rows()), 0);
    m_rest.resize(3 * static_cast<std::size_t>(m_num_vertices));
    for (Index v = 0; v < m_num_vertices; ++v)
        for (int k = 0; k < 3; ++k)
            m_rest[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(k)] = rest(v, k);
}

bool EdgeFaceDetector::crosses_locally(Index edge, Index object, const PositionsRef& positions)
{
    const auto e = static_cast<std::size_t>(edge);
    if (m_reach.empty() || m_edge_object[e] != object || !m_self[static_cast<std::size_t>(object)]) return false;
    const Triangles& faces = m_result.faces;
    const Index ev[2] = {m_result.edges(edge, 0), m_result.edges(edge, 1)};
    if (!m_local_listed[e]) {
        // Once per edge: the faces of its object that share no tet with it and have a vertex within reach at rest.
        m_local_listed[e] = 1;
        for (Index f = 0; f < faces.rows(); ++f) {
            const Index fv[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
            if (m_face_object[static_cast<std::size_t>(f)] == object && near_at_rest(ev, fv, object) &&
                !near_in_mesh(ev, fv))
                m_local_faces[e].push_back(static_cast<std::int32_t>(f));
        }
    }
    const Vec3 p(positions(ev[0], 0), positions(ev[0], 1), positions(ev[0], 2)),
        q(positions(ev[1], 0), positions(ev[1], 1), positions(ev[1], 2));
    for (const std::int32_t f : m_local_faces[e]) {
        const Index fv[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
        const Vec3 a(positions(fv[0], 0), positions(fv[0], 1), positions(fv[0], 2)),
            b(positions(fv[1], 0), positions(fv[1], 1), positions(fv[1], 2)),
            c(positions(fv[2], 0), positions(fv[2], 1), positions(fv[2], 2));
        if (edge_face_crossing(p.data(), q.data(), a.data(), b.data(), c.data()).crosses) return true;
    }
    return false;
}

bool EdgeFaceDetector::near_in_mesh(const Index* e, const Index* f) const
{
    for (int i = 0; i < 2; ++i) {
        const auto begin = m_neighbours.begin() + m_offsets[static_cast<std::size_t>(e[i])];
        const auto end = m_neighbours.begin() + m_offsets[static_cast<std::size_t>(e[i]) + 1];
        for (int k = 0; k < 3; ++k)
            if (e[i] == f[k] || std::binary_search(begin, end, f[k])) return true;
    }
    return false;
}

bool EdgeFaceDetector::near_at_rest(const Index* e, const Index* f, Index object) const
{
    if (m_reach.empty()) return false;
    const double r = m_reach[static_cast<std::size_t>(object)];
    for (int i = 0; i < 2; ++i) {
        const double* a = m_rest.data() + 3 * static_cast<std::size_t>(e[i]);
        for (int k = 0; k < 3; ++k) {
            const double* b = m_rest.data() + 3 * static_cast<std::size_t>(f[k]);
            const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
            if (dx * dx + dy * dy + dz * dz < r * r) return true;
        }
    }
    return false;
}

bool EdgeFaceDetector::local_at_rest(Index e, const Index* ev, Index f, const Index* fv, Index object) const
{
    if (m_reach.empty()) return false;
    // The rest spheres first: every vertex pair within reach, or every one beyond it (a relative slack of 1e-12 for
    // the rounding of the centres, radii and distance); between, the six distances decide.
    const double r = m_reach[static_cast<std::size_t>(object)];
    const Sphere &a = m_edge_sphere[static_cast<std::size_t>(e)], &b = m_face_sphere[static_cast<std::size_t>(f)];
    const double dx = a.c[0] - b.c[0], dy = a.c[1] - b.c[1], dz = a.c[2] - b.c[2];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if ((d + a.r + b.r) * (1 + 1e-12) < r) return true;
    if (d - a.r - b.r > r * (1 + 1e-12)) return false;
    return near_at_rest(ev, fv, object);
}

void EdgeFaceDetector::set_skin(double skin)
{
    if (!(skin >= 0) || !std::isfinite(skin))
        throw Error("EdgeFaceDetector::set_skin: skin must be a finite length >= 0, found " + std::to_string(skin));
    m_skin = skin;
    m_kept_edge.clear();
    m_kept_face.clear();
    m_kept_valid = false;
    m_paused = false;
    m_reuses = 0;
}

// The displacements d = x − x_ref of the boundary vertices: per axis their span [lo, hi] must be narrower than
// 2 × limit (then each lies within `limit` of the span's centre, the common translation). The computed d and span
// carry rounding errors of at most 2^-53 of their magnitudes each: the span is compared with 2 × limit less 2^-50
// of the largest |d| and with a relative slack of 1e-12, so a passed check holds for the exact displacements.
bool EdgeFaceDetector::moved_less_than(const PositionsRef& x, double limit) const
{
    constexpr double inf = std::numeric_limits<double>::infinity();
    double lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    const double* r = m_reference.data();
    for (const Index v : m_boundary_vertices) {
        for (int k = 0; k < 3; ++k) {
            const double d = x(v, k) - r[k];
            if (!(std::abs(d) < inf)) return false; // NaN or infinite
            lo[k] = std::min(lo[k], d);
            hi[k] = std::max(hi[k], d);
        }
        r += 3;
    }
    if (m_boundary_vertices.empty()) return true;
    for (int k = 0; k < 3; ++k) {
        const double big = std::max(std::abs(lo[k]), std::abs(hi[k]));
        if (!(hi[k] - lo[k] < 2 * limit * (1 - 1e-12) - std::ldexp(big, -50))) return false;
    }
    return true;
}

void EdgeFaceDetector::remember(const PositionsRef& x)
{
    m_reference.resize(3 * m_boundary_vertices.size());
    double* r = m_reference.data();
    for (const Index v : m_boundary_vertices) {
        for (int k = 0; k < 3; ++k)
            r[k] = x(v, k);
        r += 3;
    }
}

const EdgeFaceResult& EdgeFaceDetector::find(const PositionsRef& positions, int threads)
{
    detail::check_positions(positions, m_num_vertices);
    check_threads(threads, "EdgeFaceDetector::find: threads");
    threads = team_threads(threads);
    m_result.contacts.clear();
    m_result.candidates = 0;
    m_result.reused = 0;
    if (!(m_skin > 0)) {
        find_full(positions, threads, 0.0, false);
    } else if (m_kept_valid && moved_less_than(positions, 0.5 * m_skin)) {
        // Every boundary vertex within s/2 (per axis, less the common translation) of where the full find saw it:
        // each pair whose boxes meet now had grown boxes that met then (docs/ccd.md, "Candidate reuse").
        ++m_reuses;
        m_result.reused = 1;
        find_kept(positions, threads);
    } else {
        if (m_kept_valid && m_reuses == 0) {
            m_paused = true; // the last grown boxes bought nothing: hash without them
        } else if (m_paused && !m_reference.empty() && moved_less_than(positions, 0.25 * m_skin)) {
            m_paused = false; // slow enough since the previous find for kept pairs to last
        }
        find_full(positions, threads, m_paused ? 0.0 : 0.5 * m_skin, !m_paused);
        remember(positions);
        m_reuses = 0;
    }
    m_result.kept_candidates = static_cast<std::int64_t>(m_kept_edge.size());
    std::sort(m_result.contacts.begin(), m_result.contacts.end(),
              [](const EdgeFaceContact& x, const EdgeFaceContact& y) {
                  return x.edge < y.edge || (x.edge == y.edge && x.face < y.face);
              });
    return m_result;
}

void EdgeFaceDetector::find_full(const PositionsRef& positions, int threads, double grow, bool keep)
{
    const Triangles& faces = m_result.faces;
    const Edges& edges = m_result.edges;
    auto point = [&](Index v) { return Vec3(positions(v, 0), positions(v, 1), positions(v, 2)); };
    FaceGrid grid;
    grid.build(positions, faces, edges, grow);

    struct Part {
        std::vector<EdgeFaceContact> found;
        std::vector<std::int32_t> edge, face; ///< the pairs kept for reuse
        std::int64_t candidates = 0;
    };
    std::vector<Part> parts(static_cast<std::size_t>(threads));
    const std::int64_t ne = edges.rows();
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(threads) if (threads > 1)
#endif
    {
        const int rank = detail::team_rank(), size = detail::team_size();
        Part& part = parts[static_cast<std::size_t>(rank)];
        std::int64_t begin = 0, end = 0;
        detail::team_split(ne, rank, size, begin, end);
        std::vector<std::int32_t> stamp(static_cast<std::size_t>(faces.rows()), -1), hits;
        for (std::int64_t e = begin; e < end; ++e) {
            const Index ev[2] = {edges(e, 0), edges(e, 1)};
            const Index eo = m_edge_object[static_cast<std::size_t>(e)];
            const bool e_static = m_static[static_cast<std::size_t>(eo)] != 0;
            const Vec3 p = point(ev[0]), q = point(ev[1]);
            Box own;
            for (int k = 0; k < 3; ++k) {
                own.lo[k] = std::min(p[k], q[k]);
                own.hi[k] = std::max(p[k], q[k]);
            }
            const Vec3 lo = (p.cwiseMin(q).array() - grow).matrix(), hi = (p.cwiseMax(q).array() + grow).matrix();
            grid.for_box(lo, hi, stamp.data(), static_cast<std::int32_t>(e), hits, [&](Index f) {
                const Index fv[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
                const Index fo = m_face_object[static_cast<std::size_t>(f)];
                if (e_static && m_static[static_cast<std::size_t>(fo)]) return;
                // Without kept pairs only the pairs whose own boxes meet matter.
                if (!keep && !boxes_meet(own, grid.tight(f))) return;
                if (eo == fo) {
                    if (!m_self[static_cast<std::size_t>(eo)] || local_at_rest(static_cast<Index>(e), ev, f, fv, eo) ||
                        near_in_mesh(ev, fv))
                        return;
                } else if (ev[0] == fv[0] || ev[0] == fv[1] || ev[0] == fv[2] || ev[1] == fv[0] || ev[1] == fv[1] ||
                           ev[1] == fv[2]) {
                    return;
                }
                if (keep) {
                    part.edge.push_back(static_cast<std::int32_t>(e));
                    part.face.push_back(static_cast<std::int32_t>(f));
                }
                // The grown boxes met; a crossing point lies in both own boxes.
                if (!boxes_meet(own, grid.tight(f))) return;
                ++part.candidates;
                EdgeFaceContact ct;
                if (crossing_contact(static_cast<Index>(e), ev, p, q, f, fv, positions, eo, fo, ct))
                    part.found.push_back(ct);
            });
        }
    }
    m_kept_edge.clear();
    m_kept_face.clear();
    for (const Part& part : parts) {
        m_result.contacts.insert(m_result.contacts.end(), part.found.begin(), part.found.end());
        m_result.candidates += part.candidates;
        // Each part holds a contiguous range of edges, in order: the kept pairs come out by edge.
        m_kept_edge.insert(m_kept_edge.end(), part.edge.begin(), part.edge.end());
        m_kept_face.insert(m_kept_face.end(), part.face.begin(), part.face.end());
    }
    m_kept_valid = keep;
}

void EdgeFaceDetector::find_kept(const PositionsRef& positions, int threads)
{
    const Triangles& faces = m_result.faces;
    const Edges& edges = m_result.edges;
    const auto nk = static_cast<std::int64_t>(m_kept_edge.size());
    // A team only where the pairs are many (a region costs more than testing a few thousand).
    if (nk < 16384) threads = 1;
    std::vector<std::vector<EdgeFaceContact>> found(static_cast<std::size_t>(threads));
    std::vector<std::int64_t> candidates(static_cast<std::size_t>(threads), 0);
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(threads) if (threads > 1)
#endif
    {
        const int rank = detail::team_rank(), size = detail::team_size();
        auto& out = found[static_cast<std::size_t>(rank)];
        std::int64_t& count = candidates[static_cast<std::size_t>(rank)];
        std::int64_t begin = 0, end = 0;
        detail::team_split(nk, rank, size, begin, end);
        Index last = -1;
        Index ev[2] = {0, 0};
        Vec3 p, q;
        Box own{};
        for (std::int64_t i = begin; i < end; ++i) {
            const Index e = m_kept_edge[static_cast<std::size_t>(i)];
            if (e != last) {
                last = e;
                ev[0] = edges(e, 0);
                ev[1] = edges(e, 1);
                p = Vec3(positions(ev[0], 0), positions(ev[0], 1), positions(ev[0], 2));
                q = Vec3(positions(ev[1], 0), positions(ev[1], 1), positions(ev[1], 2));
                for (int k = 0; k < 3; ++k) {
                    own.lo[k] = std::min(p[k], q[k]);
                    own.hi[k] = std::max(p[k], q[k]);
                }
            }
            const Index f = m_kept_face[static_cast<std::size_t>(i)];
            const Index fv[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
            Box box;
            for (int k = 0; k < 3; ++k) {
                const double c0 = positions(fv[0], k), c1 = positions(fv[1], k), c2 = positions(fv[2], k);
                box.lo[k] = std::min({c0, c1, c2});
                box.hi[k] = std::max({c0, c1, c2});
            }
            if (!boxes_meet(own, box)) continue;
            ++count;
            EdgeFaceContact ct;
            if (crossing_contact(e, ev, p, q, f, fv, positions, m_edge_object[static_cast<std::size_t>(e)],
                                 m_face_object[static_cast<std::size_t>(f)], ct))
                out.push_back(ct);
        }
    }
    for (int r = 0; r < threads; ++r) {
        const auto& part = found[static_cast<std::size_t>(r)];
        m_result.contacts.insert(m_result.contacts.end(), part.begin(), part.end());
        m_result.candidates += candidates[static_cast<std::size_t>(r)];
    }
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
