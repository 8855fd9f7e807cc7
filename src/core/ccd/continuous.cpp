// Continuous detection on tet meshes (include/tethash/continuous.hpp): boundary primitives, swept boxes in two
// bounding-volume trees (the core's triangle tree, each box given as the "triangle" lo, hi, centre, whose corner box
// is the box itself), the narrow phase of ccd.hpp, per-thread lists merged and sorted.
#include "tethash/continuous.hpp"

#include "../team.hpp"
#include "../triangle_bvh.hpp"
#include "boundary_edges.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace tethash::ccd {
namespace {

using Vec3 = Eigen::Vector3d;

struct Box {
    Vec3 lo, hi;
};

bool overlap(const Box& a, const Box& b)
{
    return !((a.lo.array() > b.hi.array()).any() || (b.lo.array() > a.hi.array()).any());
}

void check_input(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1)
{
    if (x0.rows() != x1.rows())
        throw Error("detect_continuous: the start positions have " + std::to_string(x0.rows()) +
                    " rows, the end positions " + std::to_string(x1.rows()));
    const Index n = static_cast<Index>(x0.rows());
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
        for (int c = 0; c < 4; ++c)
            if (tets(t, c) < 0 || tets(t, c) >= n)
                throw Error("detect_continuous: tet " + std::to_string(t) + " names vertex " +
                            std::to_string(tets(t, c)) + ", outside [0, " + std::to_string(n) + ")");
    for (const PositionsRef* x : {&x0, &x1})
        for (Eigen::Index i = 0; i < x->rows(); ++i)
            for (int k = 0; k < 3; ++k)
                if (!(std::abs((*x)(i, k)) <= 1e50))
                    throw Error(std::string("detect_continuous: coordinate ") + std::to_string(k) + " of vertex " +
                                std::to_string(i) + " at " + (x == &x0 ? "the start" : "the end") +
                                " is not finite or above 1e50 in magnitude");
}

/// Boundary faces, their edges and their vertices.
struct Boundary {
    Triangles faces;
    Edges edges;
    std::vector<Index> vertices; ///< increasing
};

Boundary boundary_of(const TetsRef& tets)
{
    Boundary b;
    b.faces = boundary_faces(tets);
    b.edges = detail::edges_of_faces(b.faces);
    b.vertices.assign(b.faces.data(), b.faces.data() + b.faces.size());
    std::sort(b.vertices.begin(), b.vertices.end());
    b.vertices.erase(std::unique(b.vertices.begin(), b.vertices.end()), b.vertices.end());
    return b;
}

template <int N> Box swept_box(const PositionsRef& x0, const PositionsRef& x1, const std::array<Index, N>& ids)
{
    Box b{x0.row(ids[0]).transpose(), x0.row(ids[0]).transpose()};
    for (const Index v : ids)
        for (const PositionsRef* x : {&x0, &x1}) {
            const Vec3 p = x->row(v).transpose();
            b.lo = b.lo.cwiseMin(p);
            b.hi = b.hi.cwiseMax(p);
        }
    return b;
}

std::array<Index, 3> face_of(const Triangles& faces, Index f)
{
    return {faces(f, 0), faces(f, 1), faces(f, 2)};
}
std::array<Index, 2> edge_of(const Edges& edges, Index e)
{
    return {edges(e, 0), edges(e, 1)};
}

/// Pairs sharing a vertex are never queried (they meet at it).
bool shares_vertex(const Triangles& faces, Index v, Index f)
{
    return faces(f, 0) == v || faces(f, 1) == v || faces(f, 2) == v;
}
bool shares_vertex(const Edges& edges, Index e, Index g)
{
    return edges(e, 0) == edges(g, 0) || edges(e, 0) == edges(g, 1) || edges(e, 1) == edges(g, 0) ||
           edges(e, 1) == edges(g, 1);
}

/// The narrow phase of one pair (sharing no vertex); appends a contact when they may meet.
void vertex_face_pair(const PositionsRef& x0, const PositionsRef& x1, const Triangles& faces, Index v, Index f,
                      const CcdParams& query, std::vector<ContinuousContact>& out)
{
    const auto c = face_of(faces, f);
    const CcdResult r = vertex_face_ccd(x0.row(v).transpose(), x0.row(c[0]).transpose(), x0.row(c[1]).transpose(),
                                        x0.row(c[2]).transpose(), x1.row(v).transpose(), x1.row(c[0]).transpose(),
                                        x1.row(c[1]).transpose(), x1.row(c[2]).transpose(), query);
    if (r.hit) out.push_back({ContinuousKind::vertex_face, v, f, r.toi, r.outcome});
}

void edge_edge_pair(const PositionsRef& x0, const PositionsRef& x1, const Edges& edges, Index e, Index g,
                    const CcdParams& query, std::vector<ContinuousContact>& out)
{
    const auto a = edge_of(edges, e), b = edge_of(edges, g);
    const CcdResult r = edge_edge_ccd(x0.row(a[0]).transpose(), x0.row(a[1]).transpose(), x0.row(b[0]).transpose(),
                                      x0.row(b[1]).transpose(), x1.row(a[0]).transpose(), x1.row(a[1]).transpose(),
                                      x1.row(b[0]).transpose(), x1.row(b[1]).transpose(), query);
    if (r.hit) out.push_back({ContinuousKind::edge_edge, e, g, r.toi, r.outcome});
}

void sort_contacts(std::vector<ContinuousContact>& contacts)
{
    std::sort(contacts.begin(), contacts.end(), [](const ContinuousContact& p, const ContinuousContact& q) {
        if (p.kind != q.kind) return p.kind < q.kind;
        if (p.a != q.a) return p.a < q.a;
        return p.b < q.b;
    });
}

/// A tree over boxes: box i as the triangle (lo, hi, centre).
void build_tree(detail::TriangleBvh& tree, const std::vector<Box>& boxes)
{
    tree.build(
        static_cast<Index>(boxes.size()),
        [&](Index i, Vec3& a, Vec3& b, Vec3& c) {
            const Box& box = boxes[static_cast<std::size_t>(i)];
            a = box.lo;
            b = box.hi;
            c = 0.5 * (box.lo + box.hi);
        },
        4);
}

/// The threads a parallel loop asked for `threads` (0: all) runs on.
int thread_slots(int threads)
{
#ifdef TETHASH_HAVE_OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#endif
    return std::max(threads, 1);
}

/// The broad phase: calls vf(rank, v, f) for every boundary vertex v and face f, and ee(rank, e, g) for every pair of
/// boundary edges e < g, whose swept boxes overlap and that share no vertex, on `threads` threads (rank: the
/// calling thread's, in [0, threads)). Returns the thread count used.
template <typename VertexFace, typename EdgeEdge>
int for_each_candidate(const Boundary& bd, const PositionsRef& x0, const PositionsRef& x1, int threads,
                       const VertexFace& vf, const EdgeEdge& ee)
{
    std::vector<Box> face_boxes(static_cast<std::size_t>(bd.faces.rows())),
        edge_boxes(static_cast<std::size_t>(bd.edges.rows()));
    for (std::size_t f = 0; f < face_boxes.size(); ++f)
        face_boxes[f] = swept_box<3>(x0, x1, face_of(bd.faces, static_cast<Index>(f)));
    for (std::size_t e = 0; e < edge_boxes.size(); ++e)
        edge_boxes[e] = swept_box<2>(x0, x1, edge_of(bd.edges, static_cast<Index>(e)));
    detail::TriangleBvh face_tree, edge_tree;
    build_tree(face_tree, face_boxes);
    build_tree(edge_tree, edge_boxes);

    threads = thread_slots(threads);
    const std::int64_t nv = static_cast<std::int64_t>(bd.vertices.size()), ne = bd.edges.rows();
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel num_threads(threads) if (threads > 1)
#endif
    {
        const int rank = detail::team_rank(), size = detail::team_size();
        std::int64_t begin = 0, end = 0;
        detail::team_split(nv, rank, size, begin, end);
        for (std::int64_t i = begin; i < end; ++i) {
            const Index v = bd.vertices[static_cast<std::size_t>(i)];
            const Box vb = swept_box<1>(x0, x1, {v});
            face_tree.for_box(vb.lo, vb.hi, [&](Index f) {
                if (!overlap(vb, face_boxes[static_cast<std::size_t>(f)]) || shares_vertex(bd.faces, v, f)) return;
                vf(rank, v, f);
            });
        }
        detail::team_split(ne, rank, size, begin, end);
        for (std::int64_t e = begin; e < end; ++e) {
            const Box& eb = edge_boxes[static_cast<std::size_t>(e)];
            edge_tree.for_box(eb.lo, eb.hi, [&](Index g) {
                if (g <= e || !overlap(eb, edge_boxes[static_cast<std::size_t>(g)]) ||
                    shares_vertex(bd.edges, static_cast<Index>(e), g))
                    return;
                ee(rank, static_cast<Index>(e), g);
            });
        }
    }
    return threads;
}

} // namespace

ContinuousResult detect_continuous(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                   const ContinuousParams& params)
{
    check_input(tets, x0, x1);
    // The narrow phase checks its parameters; checked here once so that an empty scene refuses them too.
    if (!(params.query.tolerance > 0 && params.query.tolerance < 1e300) || params.query.max_iterations < 1)
        throw Error("detect_continuous: the tolerance must be positive and finite and max_iterations at least 1");
    Boundary bd = boundary_of(tets);
    ContinuousResult result;
    const auto slots = static_cast<std::size_t>(thread_slots(params.threads));
    std::vector<std::vector<ContinuousContact>> found(slots);
    std::vector<std::int64_t> vf_candidates(slots), ee_candidates(slots);
    const int threads = for_each_candidate(
        bd, x0, x1, params.threads,
        [&](int rank, Index v, Index f) {
            ++vf_candidates[static_cast<std::size_t>(rank)];
            vertex_face_pair(x0, x1, bd.faces, v, f, params.query, found[static_cast<std::size_t>(rank)]);
        },
        [&](int rank, Index e, Index g) {
            ++ee_candidates[static_cast<std::size_t>(rank)];
            edge_edge_pair(x0, x1, bd.edges, e, g, params.query, found[static_cast<std::size_t>(rank)]);
        });
    for (int r = 0; r < threads; ++r) {
        const auto& part = found[static_cast<std::size_t>(r)];
        result.contacts.insert(result.contacts.end(), part.begin(), part.end());
        result.vertex_face_candidates += vf_candidates[static_cast<std::size_t>(r)];
        result.edge_edge_candidates += ee_candidates[static_cast<std::size_t>(r)];
    }
    sort_contacts(result.contacts);
    result.faces = std::move(bd.faces);
    result.edges = std::move(bd.edges);
    return result;
}

ContinuousCandidates continuous_candidates(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                           int threads)
{
    check_input(tets, x0, x1);
    Boundary bd = boundary_of(tets);
    const auto slots = static_cast<std::size_t>(thread_slots(threads));
    std::vector<std::vector<std::array<Index, 2>>> vf(slots), ee(slots);
    const int used = for_each_candidate(
        bd, x0, x1, threads,
        [&](int rank, Index v, Index f) {
            vf[static_cast<std::size_t>(rank)].push_back({v, f});
        },
        [&](int rank, Index e, Index g) {
            ee[static_cast<std::size_t>(rank)].push_back({e, g});
        });
    ContinuousCandidates result;
    for (int r = 0; r < used; ++r) {
        result.vertex_face.insert(result.vertex_face.end(), vf[static_cast<std::size_t>(r)].begin(),
                                  vf[static_cast<std::size_t>(r)].end());
        result.edge_edge.insert(result.edge_edge.end(), ee[static_cast<std::size_t>(r)].begin(),
                                ee[static_cast<std::size_t>(r)].end());
    }
    std::sort(result.vertex_face.begin(), result.vertex_face.end());
    std::sort(result.edge_edge.begin(), result.edge_edge.end());
    result.faces = std::move(bd.faces);
    result.edges = std::move(bd.edges);
    return result;
}

ContinuousResult detect_continuous_brute_force(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                               const CcdParams& query)
{
    check_input(tets, x0, x1);
    Boundary bd = boundary_of(tets);
    ContinuousResult result;
    for (const Index v : bd.vertices)
        for (Index f = 0; f < bd.faces.rows(); ++f) {
            if (shares_vertex(bd.faces, v, f)) continue;
            ++result.vertex_face_candidates;
            vertex_face_pair(x0, x1, bd.faces, v, f, query, result.contacts);
        }
    for (Index e = 0; e < bd.edges.rows(); ++e)
        for (Index g = e + 1; g < bd.edges.rows(); ++g) {
            if (shares_vertex(bd.edges, e, g)) continue;
            ++result.edge_edge_candidates;
            edge_edge_pair(x0, x1, bd.edges, e, g, query, result.contacts);
        }
    sort_contacts(result.contacts);
    result.faces = std::move(bd.faces);
    result.edges = std::move(bd.edges);
    return result;
}

} // namespace tethash::ccd
