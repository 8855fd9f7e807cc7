// The refusal of surfaces a solid-leaf BSP tree cannot represent (bsp.hpp): too few triangles, bad indices or
// coordinates, zero-area triangles, open or non-manifold edges, inconsistent orientation, self-intersections (exact
// tests on the triangles whose boxes meet), no enclosed volume; an inward surface is turned outwards.
#include "bsp_impl.hpp"
#include "tethash/error.hpp"
#include "tethash/geometry.hpp"

#include <algorithm>
#include <tuple>

namespace tethash {

using namespace bsp_detail;

void BspImpl::check(const std::string& what)
{
    const Index n = static_cast<Index>(vertices.rows());
    const Index m = static_cast<Index>(triangles.rows());
    if (m < 4) throw Error(what + ": a closed surface needs at least 4 triangles, found " + std::to_string(m));
    for (Index i = 0; i < n; ++i)
        if (!vertices.row(i).allFinite())
            throw Error(what + ": vertex " + std::to_string(i) + " has a non-finite coordinate");
    double longest = 0;
    for (Index t = 0; t < m; ++t) {
        for (int c = 0; c < 3; ++c)
            if (triangles(t, c) < 0 || triangles(t, c) >= n)
                throw Error(what + ": triangle " + std::to_string(t) + " has vertex index " +
                            std::to_string(triangles(t, c)) + " out of range [0, " + std::to_string(n) + ")");
        if (triangles(t, 0) == triangles(t, 1) || triangles(t, 1) == triangles(t, 2) ||
            triangles(t, 2) == triangles(t, 0))
            throw Error(what + ": triangle " + std::to_string(t) + " repeats a vertex");
        for (int c = 0; c < 3; ++c)
            longest = std::max(longest, (corner(t, c) - corner(t, (c + 1) % 3)).norm());
    }
    for (Index t = 0; t < m; ++t) {
        const Vec3 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
        const double e = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
        if ((b - a).cross(c - a).norm() <= 1e-14 * e)
            throw Error(what + ": triangle " + std::to_string(t) + " has zero area (degenerate)");
    }
    // Closed and consistently oriented: every undirected edge in exactly two triangles, once each way.
    struct HalfEdge {
        Index lo, hi, t;
        bool forward;
    };
    std::vector<HalfEdge> half;
    half.reserve(static_cast<std::size_t>(3 * m));
    for (Index t = 0; t < m; ++t)
        for (int c = 0; c < 3; ++c) {
            const Index a = triangles(t, c), b = triangles(t, (c + 1) % 3);
            half.push_back({std::min(a, b), std::max(a, b), t, a < b});
        }
    std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
        return std::tie(x.lo, x.hi, x.t) < std::tie(y.lo, y.hi, y.t);
    });
    for (std::size_t i = 0; i < half.size();) {
        std::size_t j = i;
        while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi)
            ++j;
        const std::string edge = edge_text(half[i].lo, half[i].hi);
        if (j - i == 1)
            throw Error(what + ": open surface: edge " + edge + " belongs to triangle " + std::to_string(half[i].t) +
                        " only");
        if (j - i > 2)
            throw Error(what + ": non-manifold surface: edge " + edge + " belongs to " + std::to_string(j - i) +
                        " triangles");
        if (half[i].forward == half[i + 1].forward)
            throw Error(what + ": inconsistently oriented surface: triangles " + std::to_string(half[i].t) + " and " +
                        std::to_string(half[i + 1].t) + " run through edge " + edge + " the same way");
        i = j;
    }
    // Self-intersections: pairs of triangles whose boxes meet.
    tree.build(
        m,
        [&](Index t, Vec3& a, Vec3& b, Vec3& c) {
            a = corner(t, 0);
            b = corner(t, 1);
            c = corner(t, 2);
        },
        4);
    for (Index t = 0; t < m; ++t) {
        const std::array<Vec3, 3> u{corner(t, 0), corner(t, 1), corner(t, 2)};
        const Vec3 tlo = u[0].cwiseMin(u[1]).cwiseMin(u[2]), thi = u[0].cwiseMax(u[1]).cwiseMax(u[2]);
        tree.for_box(tlo, thi, [&](Index s) {
            if (s <= t) return;
            const std::array<Vec3, 3> v{corner(s, 0), corner(s, 1), corner(s, 2)};
            const Vec3 slo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), shi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
            if ((slo.array() > thi.array()).any() || (shi.array() < tlo.array()).any()) return;
            int shared = 0;
            int ct = -1, cs = -1; // a shared corner of each
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    if (triangles(t, i) == triangles(s, j)) {
                        ++shared;
                        ct = i;
                        cs = j;
                    }
            bool meet = false;
            if (shared == 0) {
                meet = triangles_meet(u, v);
            } else if (shared == 1) {
                meet = triangles_meet_beyond_vertex(u[ct], u[(ct + 1) % 3], u[(ct + 2) % 3], v[(cs + 1) % 3],
                                                    v[(cs + 2) % 3]);
            } else {
                // Sharing an edge: they overlap only if folded onto each other (coplanar, same side of the edge).
                int ot = 0, os = 0; // the corners not on the shared edge
                for (int i = 0; i < 3; ++i) {
                    bool in_s = false, in_t = false;
                    for (int j = 0; j < 3; ++j) {
                        in_s = in_s || triangles(t, i) == triangles(s, j);
                        in_t = in_t || triangles(s, i) == triangles(t, j);
                    }
                    if (!in_s) ot = i;
                    if (!in_t) os = i;
                }
                const Vec3& a = u[(ot + 1) % 3];
                const Vec3& b = u[(ot + 2) % 3];
                if (orient(a, b, u[ot], v[os]) == 0) {
                    const Vec3 w = lift_point(a, b, u[ot]);
                    meet = orient2(a, b, u[ot], w) == orient2(a, b, v[os], w);
                }
            }
            if (meet)
                throw Error(what + ": self-intersecting surface: triangles " + std::to_string(t) + " and " +
                            std::to_string(s) + " intersect");
        });
    }
    // Orientation: the enclosed volume must be positive; turn an inward surface outwards.
    double volume = 0;
    const Vec3 origin = vertex(0);
    for (Index t = 0; t < m; ++t)
        volume += (corner(t, 0) - origin).dot((corner(t, 1) - origin).cross(corner(t, 2) - origin));
    if (!(std::abs(volume) > 1e-14 * longest * longest * longest))
        throw Error(what + ": the surface encloses no volume");
    if (volume < 0) {
        triangles.col(1).swap(triangles.col(2));
        stats.flipped = true;
    }
}

} // namespace tethash
