#include "proximity.hpp"

#include "core/team.hpp"

#include "core/hash/box_grid.hpp"

#include "tethash/geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tethash::sim {

namespace {

using Vec3 = Eigen::Vector3d;

/// A vertex's reach is this many times its travel in the substep ...
constexpr double radius_travel = 1.5;
/// ... at most this many mean edges: the faces a vertex looks at grow with its cube. On a crumpling sheet (every
/// vertex moving) twice this cap cost twice as much per step for about as many far self-penetrations
/// (docs/simulator.md, "Figures behind the code's constants").
constexpr double radius_edges = 0.25;
/// The grid's cell, in mean edges. Each face is entered in every cell its grown box meets (tens at one mean edge);
/// at two, a face meets fewer cells and a query reads more faces per cell, and the stage cost less on every
/// shared-mesh drop measured; at three it cost more again (docs/simulator.md, "Open").
constexpr double cell_edges = 2.0;
/// Two objects thrown at each other: their whole surfaces close at once, so the cap is wider (it costs only while
/// they approach fast).
constexpr double pair_edges = 2.0;

} // namespace

void Proximity::setup(const TetMesh& mesh, const Positions& rest, const Model& model,
                      const std::vector<ObjectOptions>& options, double margin_edges, bool speculative,
                      double reach_edges)
{
    m_speculative = speculative;
    m_model = &model;
    m_rest = rest;
    m_faces.clear();
    m_vertices.clear();
    const size_t objects = model.object_mean_edge.size();
    m_margin.assign(objects, 0.0);
    m_reach2.assign(objects, -1.0);
    m_static.assign(objects, 0);
    m_edge = 0;
    m_margin_max = 0;
    for (size_t o = 0; o < objects; ++o) {
        const ObjectOptions opt = o < options.size() ? options[o] : ObjectOptions{};
        const double edge = model.object_mean_edge[o];
        m_static[o] = opt.is_static || !(edge > 0) ? 1 : 0;
        if (m_static[o]) continue;
        m_margin[o] = margin_edges * edge;
        m_margin_max = std::max(m_margin_max, m_margin[o]);
        if (opt.self_collision) m_reach2[o] = reach_edges * edge * reach_edges * edge;
        m_edge = std::max(m_edge, edge);
    }
    if (!(m_edge > 0)) return; // nothing moves

    const Triangles tri = boundary_faces(mesh.tets);
    const Adjacency vt = vertex_tets(mesh.tets, mesh.num_vertices());
    std::vector<char> is_boundary(static_cast<size_t>(mesh.num_vertices()), 0);
    for (Index f = 0; f < tri.rows(); ++f) {
        Face fc{};
        for (int k = 0; k < 3; ++k)
            fc.v[k] = tri(f, k);
        fc.tet = -1;
        // The one tet holding the face: among the tets of its first corner, the one with the other two.
        for (Index a = vt.offsets[static_cast<size_t>(fc.v[0])]; a < vt.offsets[static_cast<size_t>(fc.v[0]) + 1];
             ++a) {
            const Index t = vt.neighbours[static_cast<size_t>(a)];
            int found = 0;
            for (int c = 0; c < 4; ++c)
                for (int k = 0; k < 3; ++k)
                    if (mesh.tets(t, c) == fc.v[k]) {
                        fc.slot[k] = c;
                        ++found;
                    }
            if (found == 3) {
                fc.tet = t;
                break;
            }
        }
        if (fc.tet < 0) continue; // cannot happen for a face of boundary_faces
        fc.opp = mesh.tets(fc.tet, 6 - fc.slot[0] - fc.slot[1] - fc.slot[2]);
        fc.object = mesh.tet_object.empty() ? 0 : mesh.tet_object[static_cast<size_t>(fc.tet)];
        // The face's rest-state sphere (centroid, farthest corner), for the local test in bulk.
        const Vec3 centre = (rest.row(fc.v[0]) + rest.row(fc.v[1]) + rest.row(fc.v[2])).transpose() / 3.0;
        fc.rest_centre = centre;
        fc.rest_radius = 0;
        for (Index v : fc.v)
            fc.rest_radius = std::max(fc.rest_radius, (rest.row(v).transpose() - centre).norm());
        m_faces.push_back(fc);
        for (Index v : fc.v)
            is_boundary[static_cast<size_t>(v)] = 1;
    }
    for (Index i = 0; i < mesh.num_vertices(); ++i)
        if (is_boundary[static_cast<size_t>(i)]) m_vertices.push_back(i);
    // Vertices and faces in Morton order of their rest positions: consecutive queries read the same cells and
    // consecutive faces write to nearby ones (a real mesh's cells take megabytes: out of the cache in index order).
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (Index i : m_vertices) {
        lo = lo.cwiseMin(rest.row(i).transpose());
        hi = hi.cwiseMax(rest.row(i).transpose());
    }
    const double span = std::max((hi - lo).maxCoeff(), 1e-300);
    auto morton = [&](const Vec3& q) {
        std::uint64_t code = 0;
        for (int k = 0; k < 3; ++k) {
            const auto c = static_cast<std::uint64_t>(std::clamp((q[k] - lo[k]) / span, 0.0, 1.0) * 1023.0);
            for (int b = 0; b < 10; ++b)
                code |= ((c >> b) & 1u) << (3 * b + k);
        }
        return code;
    };
    std::vector<std::pair<std::uint64_t, Index>> order;
    for (Index i : m_vertices)
        order.emplace_back(morton(rest.row(i).transpose()), i);
    std::sort(order.begin(), order.end());
    for (size_t k = 0; k < order.size(); ++k)
        m_vertices[k] = order[k].second;
    order.clear();
    for (size_t f = 0; f < m_faces.size(); ++f)
        order.emplace_back(morton(m_faces[f].rest_centre), static_cast<Index>(f));
    std::sort(order.begin(), order.end());
    std::vector<Face> sorted;
    sorted.reserve(m_faces.size());
    for (const auto& [code, f] : order)
        sorted.push_back(m_faces[static_cast<size_t>(f)]);
    m_faces.swap(sorted);
    m_vertex_margin.assign(static_cast<size_t>(mesh.num_vertices()), 0.0);
    for (Index i : m_vertices)
        m_vertex_margin[static_cast<size_t>(i)] =
            m_margin[static_cast<size_t>(model.vertex_object[static_cast<size_t>(i)])];
    m_first = true;
}

double Proximity::margin(Index p) const
{
    return m_vertex_margin.empty() ? 0.0 : m_vertex_margin[static_cast<size_t>(p)];
}

// Each boundary vertex's reach: 1.5 × its travel in the substep relative to its object's mean motion (a body
// falling or thrown as a whole does not close its own gaps), at most radius_edges mean edges; each pair of objects
// closes on each other by 1.5 × their mean velocities' difference × h, at most pair_edges mean edges.
void Proximity::motion(const Positions& v, double h)
{
    const Model& model = *m_model;
    const std::vector<char>& fixed = model.fixed;
    const size_t objects = m_margin.size();
    m_mean_v.assign(objects, Vec3::Zero());
    m_object_mass.assign(objects, 0.0);
    for (Index i = 0; i < v.rows(); ++i) {
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(i)]);
        const double m = model.mass[static_cast<size_t>(i)];
        if (!fixed[static_cast<size_t>(i)]) m_mean_v[o] += m * v.row(i).transpose();
        m_object_mass[o] += m;
    }
    for (size_t o = 0; o < objects; ++o)
        if (m_object_mass[o] > 0) m_mean_v[o] /= m_object_mass[o];
    m_pair_now.assign(objects * objects, 0.0);
    for (size_t a = 0; a < objects; ++a)
        for (size_t b = 0; b < objects; ++b)
            if (a != b)
                m_pair_now[a * objects + b] =
                    m_speculative
                        ? std::min(radius_travel * (m_mean_v[a] - m_mean_v[b]).norm() * h, pair_edges * m_edge)
                        : 0.0;
    // The widest pair term of each object, for its vertices' query boxes.
    m_object_reach.assign(objects, 0.0);
    for (size_t a = 0; a < objects; ++a)
        for (size_t b = 0; b < objects; ++b)
            if (a != b && !(m_static[a] && m_static[b]))
                m_object_reach[a] = std::max(m_object_reach[a], m_pair_now[a * objects + b]);
    const double cap = radius_edges * m_edge;
    m_reach.resize(static_cast<size_t>(v.rows()));
    for (Index i : m_vertices) {
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(i)]);
        const double travel = fixed[static_cast<size_t>(i)] ? 0.0 : (v.row(i).transpose() - m_mean_v[o]).norm() * h;
        m_reach[static_cast<size_t>(i)] = m_speculative ? std::min(radius_travel * travel, cap) : 0.0;
    }
}

double Proximity::face_reach(const std::vector<double>& reach, const Face& f)
{
    return std::max(
        {reach[static_cast<size_t>(f.v[0])], reach[static_cast<size_t>(f.v[1])], reach[static_cast<size_t>(f.v[2])]});
}

void Proximity::hash_faces(const Positions& x)
{
    const size_t nf = m_faces.size();
    size_t buckets = 1;
    while (buckets < 2 * nf)
        buckets <<= 1;
    // Called alone or by every thread of the update's region: each its part of the faces.
    const auto box_of = [&](std::int32_t i, double lo[3], double hi[3]) {
        const Face& fc = m_faces[static_cast<size_t>(i)];
        const double grow = face_reach(m_reach, fc) + m_margin_max;
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min({x(fc.v[0], k), x(fc.v[1], k), x(fc.v[2], k)}) - grow;
            hi[k] = std::max({x(fc.v[0], k), x(fc.v[1], k), x(fc.v[2], k)}) + grow;
        }
    };
    m_grid.build(cell_edges * m_edge, buckets, nf, box_of, tethash::detail::team_rank(), tethash::detail::team_size());
}

// Inlined into query_cells' loop: the query's fields stay in registers, as in one function.
__attribute__((always_inline)) inline void Proximity::visit_face(Query& q, Scratch& s, std::int32_t f,
                                                                 const Positions& x) const
{
    const Face& fc = m_faces[static_cast<size_t>(f)];
    const Index p = q.p, op = q.op;
    bool near_rest = false; // the corners decide whether the face is local (below)
    if (fc.object == op) {
        if (q.reach2 < 0) return; // self-collision off
        // Squared: dr + radius < local_reach, dr − radius < far_reach (dr the centre's distance).
        const double dr2 = (fc.rest_centre - q.rp).squaredNorm();
        const double inner = q.local_reach - fc.rest_radius, outer = q.far_reach + fc.rest_radius;
        if (inner > 0 && dr2 < inner * inner) return; // every corner near: local
        near_rest = dr2 < outer * outer;
    } else if (m_static[static_cast<size_t>(op)] && m_static[static_cast<size_t>(fc.object)]) {
        return;
    }
    if (fc.v[0] == p || fc.v[1] == p || fc.v[2] == p) return;
    const std::vector<char>& fixed = m_model->fixed;
    if (fixed[static_cast<size_t>(p)] && fixed[static_cast<size_t>(fc.v[0])] && fixed[static_cast<size_t>(fc.v[1])] &&
        fixed[static_cast<size_t>(fc.v[2])])
        return;
    if (near_rest) {
        bool local = false;
        for (Index c : fc.v)
            local = local || (m_rest.row(c).transpose() - q.rp).squaredNorm() < q.reach2;
        if (local) return;
    }
    const Vec3 a = x.row(fc.v[0]).transpose(), bb = x.row(fc.v[1]).transpose(), c = x.row(fc.v[2]).transpose();
    const Vec3 cp = closest_point_on_triangle(q.xp, a, bb, c);
    const double d2 = (q.xp - cp).squaredNorm();
    const size_t objects = m_margin.size();
    const double watch =
        m_margin_max + q.r + face_reach(m_reach, fc) +
        (op == fc.object ? 0.0 : m_pair_now[static_cast<size_t>(op) * objects + static_cast<size_t>(fc.object)]);
    if (d2 >= watch * watch) return;
    q.clearance = std::min(q.clearance, d2);
    // The vertex must be on the outer side of the face (else it is inside, or beside the face's back: the
    // penetration response or another face answers).
    Vec3 n = (bb - a).cross(c - a);
    if (n.dot(x.row(fc.opp).transpose() - a) > 0) n = -n;
    if (!((q.xp - cp).dot(n) > 0)) return;
    const double d = std::sqrt(d2);
    auto it = std::find_if(s.best.begin(), s.best.end(), [&](const Best& bs) { return bs.object == fc.object; });
    if (it == s.best.end())
        s.best.push_back({fc.object, f, d, cp});
    else if (d < it->dist || (d == it->dist && f < it->face))
        *it = {fc.object, f, d, cp};
}

void Proximity::query_cells(Query& q, Scratch& s, const Positions& x) const
{
    const double rq = q.r + m_object_reach[static_cast<size_t>(q.op)]; // the query box: any partner object
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = q.xp[k] - rq;
        hi[k] = q.xp[k] + rq;
    }
    // A face met twice changes neither the nearest face per object nor the clearance: a query of one cell takes no
    // stamps.
    m_grid.query(lo, hi, s.stamp.data(), static_cast<std::int32_t>(q.p), s.hits, true,
                 [&](std::int32_t f) { visit_face(q, s, f, x); });
}

void Proximity::keep_contacts(const Query& q, Scratch& s, const Positions& x, const std::vector<Contact>& inside,
                              std::vector<Contact>& out)
{
    const Index p = q.p;
    std::sort(s.best.begin(), s.best.end(), [](const Best& a, const Best& b) { return a.object < b.object; });
    // The vertex's penetration contacts (`inside` is sorted by vertex): the objects it is inside answer for it.
    const auto in_begin =
        std::lower_bound(inside.begin(), inside.end(), p, [](const Contact& c, Index vtx) { return c.vertex < vtx; });
    auto in_end = in_begin;
    while (in_end != inside.end() && in_end->vertex == p)
        ++in_end;
    // The vertex's margin never exceeds the clearance it has had: a body that starts nearer than the margin to
    // another (stacked, resting, touching) is not pushed apart by it; the margin grows back as it separates.
    const double clearance = in_begin != in_end ? 0.0 : q.clearance; // penetrating: no clearance at all
    double& vm = m_vertex_margin[static_cast<size_t>(p)];
    const double full = m_margin[static_cast<size_t>(q.op)];
    vm = std::min(full, m_first ? std::sqrt(clearance) : std::max(vm, std::sqrt(clearance)));
    for (const Best& bs : s.best)
        if (std::none_of(in_begin, in_end, [&](const Contact& c) { return c.tet_object == bs.object; }))
            out.push_back(margin_contact(x, p, q.op, bs.object, bs.face, bs.dist, bs.q));
}

void Proximity::query_range(size_t begin, size_t end, Scratch& s, const Positions& x,
                            const std::vector<Contact>& inside, std::vector<Contact>& out)
{
    const Model& model = *m_model;
    Query q;
    for (size_t i = begin; i < end; ++i) {
        const Index p = m_vertices[i];
        q.p = p;
        q.op = model.vertex_object[static_cast<size_t>(p)];
        q.xp = x.row(p).transpose();
        q.rp = m_rest.row(p).transpose();
        q.r = m_reach[static_cast<size_t>(p)];
        q.clearance = std::numeric_limits<double>::infinity();
        // The local reach with a little slack for rounding: a face whose rest sphere lies wholly inside
        // `local_reach` is local; one wholly beyond `far_reach` is not; between, its corners decide.
        q.reach2 = m_reach2[static_cast<size_t>(q.op)];
        q.local_reach = q.reach2 > 0 ? std::sqrt(q.reach2) * (1 - 1e-5) : -1.0;
        q.far_reach = q.reach2 > 0 ? std::sqrt(q.reach2) * (1 + 1e-5) : -1.0;
        s.best.clear();
        query_cells(q, s, x);
        keep_contacts(q, s, x, inside, out);
    }
}

void Proximity::update(const Positions& x, const Positions& v, double h, const std::vector<Contact>& inside,
                       std::vector<Contact>& out)
{
    if (m_faces.empty()) return;
    motion(v, h);
    const size_t nv = m_vertices.size();
    const int threads = nv >= 1024 ? m_threads : 1;
    // A scratch per thread of this update, its face stamps cleared (the tags, vertex ids, repeat between updates).
    m_scratch.resize(static_cast<size_t>(threads));
    for (Scratch& sc : m_scratch)
        sc.stamp.assign(m_faces.size(), -1);
    if (threads == 1) {
        hash_faces(x);
        query_range(0, nv, m_scratch[0], x, inside, out);
    } else {
        // One region: the team builds the faces' grid (the same grid at any team size), then each thread queries
        // its contiguous range of vertices into its own contacts, joined in thread order: the contacts of one
        // thread, in vertex order. (Each vertex writes only its own margin.)
        for (Scratch& sc : m_scratch)
            sc.out.clear();
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(threads)
#endif
        {
            hash_faces(x);
            const int t = tethash::detail::team_rank(), parts = tethash::detail::team_size();
            std::int64_t begin = 0, end = 0;
            tethash::detail::team_split(static_cast<std::int64_t>(nv), t, parts, begin, end);
            Scratch& sc = m_scratch[static_cast<size_t>(t)];
            query_range(static_cast<size_t>(begin), static_cast<size_t>(end), sc, x, inside, sc.out);
        }
        for (const Scratch& sc : m_scratch)
            out.insert(out.end(), sc.out.begin(), sc.out.end());
    }
    m_first = false;
}

Contact Proximity::margin_contact(const Positions& x, Index p, Index op, Index object, Index face, double dist,
                                  const Eigen::Vector3d& q) const
{
    const Face& fc = m_faces[static_cast<size_t>(face)];
    const Vec3 a = x.row(fc.v[0]).transpose(), b = x.row(fc.v[1]).transpose(), c = x.row(fc.v[2]).transpose();
    // Barycentric coordinates of the closest point on the face (areas; a degenerate face: equal shares).
    const Vec3 n = (b - a).cross(c - a);
    const double area2 = n.squaredNorm();
    double w[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
    if (area2 > 0) {
        w[0] = (b - q).cross(c - q).dot(n) / area2;
        w[1] = (c - q).cross(a - q).dot(n) / area2;
        w[2] = 1.0 - w[0] - w[1];
    }
    Contact ct;
    ct.vertex = p;
    ct.vertex_object = op;
    ct.tet = fc.tet;
    ct.tet_object = object;
    for (int k = 0; k < 3; ++k)
        ct.bary[fc.slot[k]] = std::clamp(w[k], 0.0, 1.0);
    ct.depth = m_vertex_margin[static_cast<size_t>(p)] - dist;
    Vec3 dir = x.row(p).transpose() - q;
    if (dist > 1e-12 * m_edge)
        dir /= dist;
    else
        dir = n.normalized() * (n.dot(x.row(fc.opp).transpose() - a) > 0 ? -1.0 : 1.0);
    for (int k = 0; k < 3; ++k)
        ct.direction[k] = dir[k];
    return ct;
}

} // namespace tethash::sim
