#include "proximity.hpp"

#include "core/simd.hpp"

#include "tethash/geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define TETHASH_X86 1
#endif

namespace tethash::sim::detail {

namespace {

std::int32_t box_filter_scalar(const float* const box[6], std::int32_t begin, std::int32_t end, const float q[6],
                               std::int32_t* hits)
{
    std::int32_t n = 0;
    for (std::int32_t e = begin; e < end; ++e) {
        const size_t u = static_cast<size_t>(e);
        if ((q[3] < box[0][u]) | (q[0] > box[3][u]) | (q[4] < box[1][u]) | (q[1] > box[4][u]) | (q[5] < box[2][u]) |
            (q[2] > box[5][u]))
            continue;
        hits[n++] = e;
    }
    return n;
}

#ifdef TETHASH_X86
/// Eight entries at a time (the columns are padded by eight, so the last group's loads stay inside).
__attribute__((target("avx2"))) std::int32_t box_filter_avx2(const float* const box[6], std::int32_t begin,
                                                             std::int32_t end, const float q[6], std::int32_t* hits)
{
    const __m256 qlo0 = _mm256_set1_ps(q[0]), qlo1 = _mm256_set1_ps(q[1]), qlo2 = _mm256_set1_ps(q[2]);
    const __m256 qhi0 = _mm256_set1_ps(q[3]), qhi1 = _mm256_set1_ps(q[4]), qhi2 = _mm256_set1_ps(q[5]);
    std::int32_t n = 0;
    for (std::int32_t e = begin; e < end; e += 8) {
        const size_t u = static_cast<size_t>(e);
        __m256 miss = _mm256_cmp_ps(qhi0, _mm256_loadu_ps(box[0] + u), _CMP_LT_OQ);
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qlo0, _mm256_loadu_ps(box[3] + u), _CMP_GT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qhi1, _mm256_loadu_ps(box[1] + u), _CMP_LT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qlo1, _mm256_loadu_ps(box[4] + u), _CMP_GT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qhi2, _mm256_loadu_ps(box[2] + u), _CMP_LT_OQ));
        miss = _mm256_or_ps(miss, _mm256_cmp_ps(qlo2, _mm256_loadu_ps(box[5] + u), _CMP_GT_OQ));
        unsigned meet = ~static_cast<unsigned>(_mm256_movemask_ps(miss)) & 0xffu;
        if (end - e < 8) meet &= (1u << (end - e)) - 1;
        while (meet) {
            hits[n++] = e + __builtin_ctz(meet);
            meet &= meet - 1;
        }
    }
    return n;
}
#endif

BoxFilter choose_box_filter()
{
#ifdef TETHASH_X86
    if (tethash::detail::avx2_kernels()) return box_filter_avx2;
#endif
    return box_filter_scalar;
}

const BoxFilter chosen_box_filter = choose_box_filter();

} // namespace

std::vector<std::pair<const char*, BoxFilter>> box_filters()
{
    std::vector<std::pair<const char*, BoxFilter>> all{{"scalar", box_filter_scalar}};
#ifdef TETHASH_X86
    if (tethash::detail::cpu_has_avx2()) all.emplace_back("avx2", box_filter_avx2);
#endif
    return all;
}

const char* box_filter_name()
{
    return chosen_box_filter == box_filter_scalar ? "scalar" : "avx2";
}

} // namespace tethash::sim::detail

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

/// Single precision rounded down / up: a filter's box that contains the double one (float's relative rounding
/// error is at most 2⁻²⁴; the margin taken is 4 × that).
float round_down(double v)
{
    const float f = static_cast<float>(v);
    return f - (std::abs(f) * 2.4e-7f + 1e-30f);
}
float round_up(double v)
{
    const float f = static_cast<float>(v);
    return f + (std::abs(f) * 2.4e-7f + 1e-30f);
}

std::uint32_t cell_hash(std::int64_t x, std::int64_t y, std::int64_t z)
{
    return static_cast<std::uint32_t>((x * 73856093) ^ (y * 19349663) ^ (z * 83492791));
}

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
    m_stamp.assign(m_faces.size(), -1);
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
    const double inv_cell = 1.0 / (cell_edges * m_edge);
    const size_t nf = m_faces.size();
    m_box.resize(nf);
    m_entries.clear();
    size_t buckets = 1;
    while (buckets < 2 * nf)
        buckets <<= 1;
    m_mask = static_cast<std::uint32_t>(buckets - 1);
    for (size_t f = 0; f < nf; ++f) {
        const Face& fc = m_faces[f];
        const double reach = face_reach(m_reach, fc);
        const double grow = reach + m_margin_max;
        Cell& box = m_box[f];
        std::int64_t lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
            const double l = std::min({x(fc.v[0], k), x(fc.v[1], k), x(fc.v[2], k)}) - grow;
            const double u = std::max({x(fc.v[0], k), x(fc.v[1], k), x(fc.v[2], k)}) + grow;
            // Single precision, rounded outwards: a filter only (the closest point decides).
            box.lo[k] = round_down(l);
            box.hi[k] = round_up(u);
            lo[k] = static_cast<std::int64_t>(std::floor(l * inv_cell));
            hi[k] = static_cast<std::int64_t>(std::floor(u * inv_cell));
        }
        box.face = static_cast<std::int32_t>(f);

        for (std::int64_t cx = lo[0]; cx <= hi[0]; ++cx)
            for (std::int64_t cy = lo[1]; cy <= hi[1]; ++cy)
                for (std::int64_t cz = lo[2]; cz <= hi[2]; ++cz)
                    m_entries.emplace_back(cell_hash(cx, cy, cz) & m_mask, static_cast<std::int32_t>(f));
    }
    m_bucket_start.assign(buckets + 1, 0);
    for (const auto& e : m_entries)
        ++m_bucket_start[e.first + 1];
    for (size_t b = 0; b < buckets; ++b)
        m_bucket_start[b + 1] += m_bucket_start[b];
    // Each bucket holds its faces' boxes in a row: a query reads them in order.
    const size_t ne = m_entries.size();
    for (int k = 0; k < 3; ++k) {
        m_cell_box[k].assign(ne + 8, std::numeric_limits<float>::infinity());
        m_cell_box[3 + k].assign(ne + 8, -std::numeric_limits<float>::infinity());
    }
    m_cell_face.resize(ne);
    m_stamp.assign(m_bucket_start.begin(), m_bucket_start.end() - 1); // the fill cursor first
    for (const auto& e : m_entries) {
        const size_t at = static_cast<size_t>(m_stamp[e.first]++);
        const Cell& b = m_box[static_cast<size_t>(e.second)];
        for (int k = 0; k < 3; ++k) {
            m_cell_box[k][at] = b.lo[k];
            m_cell_box[3 + k][at] = b.hi[k];
        }
        m_cell_face[at] = b.face;
    }
    m_stamp.assign(nf, -1);
}

// Inlined into query_cells' loop: the query's fields stay in registers, as in one function.
__attribute__((always_inline)) inline void Proximity::visit_face(Query& q, std::int32_t f, const Positions& x)
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
    if (!q.one_cell) {
        if (m_stamp[static_cast<size_t>(f)] == p) return;
        m_stamp[static_cast<size_t>(f)] = static_cast<std::int32_t>(p);
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
    auto it = std::find_if(m_best.begin(), m_best.end(), [&](const Best& bs) { return bs.object == fc.object; });
    if (it == m_best.end())
        m_best.push_back({fc.object, f, d, cp});
    else if (d < it->dist || (d == it->dist && f < it->face))
        *it = {fc.object, f, d, cp};
}

void Proximity::query_cells(Query& q, const Positions& x)
{
    const double inv_cell = 1.0 / (cell_edges * m_edge);
    const double rq = q.r + m_object_reach[static_cast<size_t>(q.op)]; // the query box: any partner object
    std::int64_t lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = static_cast<std::int64_t>(std::floor((q.xp[k] - rq) * inv_cell));
        hi[k] = static_cast<std::int64_t>(std::floor((q.xp[k] + rq) * inv_cell));
    }
    q.one_cell = lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2]; // each face once: no stamps
    // The query box in single precision, rounded outwards like the faces' boxes: lo x, y, z, hi x, y, z.
    float qbox[6];
    for (int k = 0; k < 3; ++k) {
        qbox[k] = round_down(q.xp[k] - rq);
        qbox[3 + k] = round_up(q.xp[k] + rq);
    }
    const float* const columns[6] = {m_cell_box[0].data(), m_cell_box[1].data(), m_cell_box[2].data(),
                                     m_cell_box[3].data(), m_cell_box[4].data(), m_cell_box[5].data()};
    for (std::int64_t cx = lo[0]; cx <= hi[0]; ++cx)
        for (std::int64_t cy = lo[1]; cy <= hi[1]; ++cy)
            for (std::int64_t cz = lo[2]; cz <= hi[2]; ++cz) {
                const std::uint32_t bk = cell_hash(cx, cy, cz) & m_mask;
                const std::int32_t begin = m_bucket_start[bk], end = m_bucket_start[bk + 1];
                if (m_hits.size() < static_cast<size_t>(end - begin)) m_hits.resize(static_cast<size_t>(end - begin));
                const std::int32_t hits = detail::chosen_box_filter(columns, begin, end, qbox, m_hits.data());
                for (std::int32_t hit = 0; hit < hits; ++hit)
                    visit_face(q, m_cell_face[static_cast<size_t>(m_hits[static_cast<size_t>(hit)])], x);
            }
}

void Proximity::keep_contacts(const Query& q, const Positions& x, const std::vector<Contact>& inside,
                              std::vector<Contact>& out)
{
    const Index p = q.p;
    std::sort(m_best.begin(), m_best.end(), [](const Best& a, const Best& b) { return a.object < b.object; });
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
    for (const Best& bs : m_best)
        if (std::none_of(in_begin, in_end, [&](const Contact& c) { return c.tet_object == bs.object; }))
            out.push_back(margin_contact(x, p, q.op, bs.object, bs.face, bs.dist, bs.q));
}

void Proximity::update(const Positions& x, const Positions& v, double h, const std::vector<Contact>& inside,
                       std::vector<Contact>& out)
{
    if (m_faces.empty()) return;
    motion(v, h);
    hash_faces(x);
    const Model& model = *m_model;
    Query q;
    for (Index p : m_vertices) {
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
        m_best.clear();
        query_cells(q, x);
        keep_contacts(q, x, inside, out);
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
