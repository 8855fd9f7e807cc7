// Brute-force reference: all vertices × all tets (x-sorted to skip pairs whose x-extents cannot meet).
#include "tethash/oracle.hpp"

#include "core/ccd/boundary_edges.hpp"
#include "core/hash/detect_checks.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <numeric>

namespace tethash {

std::vector<Contact> brute_force_contacts(const PositionsRef& positions, const TetsRef& tets,
                                          std::span<const Index> vertex_object, std::span<const Index> tet_object,
                                          std::span<const ObjectOptions> objects, OracleStats* stats)
{
    const Index n = static_cast<Index>(positions.rows());
    detail::check_topology(tets, n, vertex_object, tet_object);
    detail::check_positions(positions, n);
    const detail::ObjectFlags flags = detail::object_flags(vertex_object, tet_object, objects);
    auto vobj = [&](Index v) { return vertex_object.empty() ? 0 : vertex_object[v]; };
    auto tobj = [&](Index t) { return tet_object.empty() ? 0 : tet_object[t]; };

    std::vector<Index> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](Index a, Index b) {
        return positions(a, 0) < positions(b, 0) || (positions(a, 0) == positions(b, 0) && a < b);
    });
    std::vector<double> xs(n);
    for (Index i = 0; i < n; ++i)
        xs[i] = positions(order[i], 0);

    const Index m = static_cast<Index>(tets.rows());
    std::vector<std::vector<Contact>> per_tet(m);
    std::int64_t degenerate = 0, tests = 0, exact = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : degenerate, tests, exact)
    for (Index t = 0; t < m; ++t) {
        const Index ids[4] = {tets(t, 0), tets(t, 1), tets(t, 2), tets(t, 3)};
        double c[4][3];
        for (int k = 0; k < 4; ++k)
            for (int a = 0; a < 3; ++a)
                c[k][a] = positions(ids[k], a);
        const predicates::Orientation o = predicates::orient3d(c[0], c[1], c[2], c[3]);
        exact += o.exact;
        if (o.sign == 0) {
            ++degenerate;
            continue;
        }
        double lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min({c[0][a], c[1][a], c[2][a], c[3][a]});
            hi[a] = std::max({c[0][a], c[1][a], c[2][a], c[3][a]});
        }
        const Index to = tobj(t);
        const bool t_static = flags.is_static[to] != 0;
        const bool self = flags.self_collision[to] != 0;
        const auto first = std::lower_bound(xs.begin(), xs.end(), lo[0]) - xs.begin();
        const auto last = std::upper_bound(xs.begin(), xs.end(), hi[0]) - xs.begin();
        for (auto i = first; i < last; ++i) {
            const Index v = order[i];
            if (v == ids[0] || v == ids[1] || v == ids[2] || v == ids[3]) continue;
            const double p[3] = {positions(v, 0), positions(v, 1), positions(v, 2)};
            if (p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2]) continue;
            const Index vo = vobj(v);
            if (vo == to && !self) continue;
            if (t_static && flags.is_static[vo]) continue;
            ++tests;
            const predicates::InsideResult r = predicates::inside_tet(p, c[0], c[1], c[2], c[3]);
            exact += r.exact_evaluations;
            if (!r.inside) continue;
            Contact ct;
            ct.vertex = v;
            ct.tet = t;
            ct.vertex_object = vo;
            ct.tet_object = to;
            for (int k = 0; k < 4; ++k)
                ct.bary[k] = r.bary[k];
            per_tet[t].push_back(ct);
        }
    }
    std::vector<Contact> out;
    for (auto& v : per_tet)
        out.insert(out.end(), v.begin(), v.end());
    std::sort(out.begin(), out.end(), [](const Contact& a, const Contact& b) {
        return a.vertex < b.vertex || (a.vertex == b.vertex && a.tet < b.tet);
    });
    if (stats) {
        stats->degenerate_tets = degenerate;
        stats->inside_tests = tests;
        stats->exact_evaluations = exact;
    }
    return out;
}

EdgeFaceResult brute_force_edge_face_contacts(const TetsRef& tets, const PositionsRef& positions,
                                              std::span<const Index> vertex_object, std::span<const Index> tet_object,
                                              std::span<const ObjectOptions> objects)
{
    const Index n = static_cast<Index>(positions.rows());
    detail::check_topology(tets, n, vertex_object, tet_object);
    detail::check_positions(positions, n);
    const detail::ObjectFlags flags = detail::object_flags(vertex_object, tet_object, objects);
    auto vobj = [&](Index v) { return vertex_object.empty() ? Index(0) : vertex_object[static_cast<std::size_t>(v)]; };
    const Adjacency incident = vertex_tets(tets, n);
    // Whether vertices u and w are the same or lie in one tet (sorted tet lists intersect).
    auto share_tet = [&](Index u, Index w) {
        if (u == w) return true;
        const auto* a = incident.neighbours.data() + incident.offsets[static_cast<std::size_t>(u)];
        const auto* a_end = incident.neighbours.data() + incident.offsets[static_cast<std::size_t>(u) + 1];
        const auto* b = incident.neighbours.data() + incident.offsets[static_cast<std::size_t>(w)];
        const auto* b_end = incident.neighbours.data() + incident.offsets[static_cast<std::size_t>(w) + 1];
        while (a != a_end && b != b_end) {
            if (*a == *b) return true;
            if (*a < *b)
                ++a;
            else
                ++b;
        }
        return false;
    };
    EdgeFaceResult result;
    result.faces = boundary_faces(tets);
    result.edges = detail::edges_of_faces(result.faces);
    for (Index e = 0; e < result.edges.rows(); ++e)
        for (Index f = 0; f < result.faces.rows(); ++f) {
            const Index ev[2] = {result.edges(e, 0), result.edges(e, 1)};
            const Index fv[3] = {result.faces(f, 0), result.faces(f, 1), result.faces(f, 2)};
            const Index eo = vobj(ev[0]), fo = vobj(fv[0]);
            if (flags.is_static[static_cast<std::size_t>(eo)] && flags.is_static[static_cast<std::size_t>(fo)])
                continue;
            if (eo == fo && !flags.self_collision[static_cast<std::size_t>(eo)]) continue;
            bool near = false;
            for (const Index u : ev)
                for (const Index w : fv)
                    near = near || (eo == fo ? share_tet(u, w) : u == w);
            if (near) continue;
            ++result.candidates;
            double p[2][3], c[3][3];
            for (int a = 0; a < 3; ++a) {
                for (int k = 0; k < 2; ++k)
                    p[k][a] = positions(ev[k], a);
                for (int k = 0; k < 3; ++k)
                    c[k][a] = positions(fv[k], a);
            }
            const EdgeFaceCrossing x = edge_face_crossing(p[0], p[1], c[0], c[1], c[2]);
            if (!x.crosses) continue;
            EdgeFaceContact ct;
            ct.edge = e;
            ct.face = f;
            for (int k = 0; k < 2; ++k)
                ct.edge_vertices[k] = ev[k];
            for (int k = 0; k < 3; ++k) {
                ct.face_vertices[k] = fv[k];
                ct.face_bary[k] = x.face_bary[k];
            }
            ct.edge_object = eo;
            ct.face_object = fo;
            ct.edge_t = x.edge_t;
            ct.inner_end = x.inner_end;
            for (int k = 0; k < 3; ++k)
                ct.normal[k] = x.normal[k];
            result.contacts.push_back(ct);
        }
    return result;
}

} // namespace tethash
