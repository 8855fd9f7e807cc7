// Solid-leaf BSP trees of closed triangle surfaces (see bsp.hpp).
//
// Build: the surface is checked (indices, finite coordinates, zero-area triangles, closed and consistently
// oriented edges, self-intersections by exact orient3d tests on the triangles whose boxes meet), turned
// outwards if needed, and its triangles grouped by plane: a triangle joins a group when its three vertices
// are exactly on the plane of the group's first triangle (orient3d = 0) and it faces the same way. The tree
// is built over fragments of the triangles (convex polygons clipped by the planes above them): a splitter is
// chosen among the planes of the node's fragments, fragments on the splitter's plane (either facing) are used
// up, the others go in front, behind or, clipped, to both sides. An empty front is an OUT leaf (the splitter's
// face looks into it), an empty back an IN leaf. The planes are exact (orient3d on three original vertices);
// the clipping of fragments is done in floating point with a tolerance of 1e-10 × the box diagonal, which
// only decides which fragments a cell still holds (a fragment thinner than that is dropped, never a plane).
//
// Query: exact orient3d against the node's original vertices; a zero follows both children, IN if either says
// IN (the closed polyhedron is the union of the closed IN cells).
#include "../timing.hpp"
#include "bsp_impl.hpp"

#include "tethash/error.hpp"
#include "tethash/geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>

namespace tethash {

using namespace bsp_detail;

void BspImpl::group_planes()
{
    const Index m = static_cast<Index>(triangles.rows());
    triangle_group.assign(static_cast<std::size_t>(m), -1);
    std::vector<double> area(static_cast<std::size_t>(m));
    std::vector<Vec3> normal(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        const Vec3 n = (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0));
        area[static_cast<std::size_t>(t)] = n.norm();
        normal[static_cast<std::size_t>(t)] = n.normalized();
    }
    // Largest triangles first, so that each group's plane comes from its best-conditioned triangle.
    std::vector<Index> order(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t)
        order[static_cast<std::size_t>(t)] = t;
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) {
        return area[static_cast<std::size_t>(a)] > area[static_cast<std::size_t>(b)];
    });
    Index planes = 0;
    for (const Index t : order) {
        const Vec3& n = normal[static_cast<std::size_t>(t)];
        const double k = n.dot(corner(t, 0));
        Index found = -1;
        Index found_plane = -1;
        for (Index g = 0; g < static_cast<Index>(groups.size()) && found < 0; ++g) {
            const Group& gr = groups[static_cast<std::size_t>(g)];
            const double cosine = std::abs(gr.n.dot(n));
            if (cosine < 1 - 1e-9 || std::abs(gr.n.dot(corner(t, 0)) - gr.k) > tolerance) continue;
            if (side(g, corner(t, 0)) != 0 || side(g, corner(t, 1)) != 0 || side(g, corner(t, 2)) != 0) continue;
            if (gr.n.dot(n) > 0)
                found = g;
            else
                found_plane = gr.plane;
        }
        if (found < 0) {
            found = static_cast<Index>(groups.size());
            groups.push_back({t, found_plane >= 0 ? found_plane : planes++, n, k});
        }
        triangle_group[static_cast<std::size_t>(t)] = found;
    }
    stats.planes = static_cast<Index>(groups.size());
}

Index BspImpl::build(std::vector<Fragment>& fragments, Index depth)
{
    stats.depth = std::max(stats.depth, depth);
    // Candidates: the groups of (up to 32 evenly spaced) fragments; score 4 × splits + |front − back|.
    const std::size_t count = fragments.size();
    const std::size_t step = std::max<std::size_t>(1, count / 32);
    Index best = -1;
    std::int64_t best_score = 0;
    for (std::size_t i = 0; i < count; i += step) {
        const Index g = fragments[i].group;
        const Group& gr = groups[static_cast<std::size_t>(g)];
        std::int64_t front = 0, back = 0, split = 0;
        for (const Fragment& f : fragments) {
            if (groups[static_cast<std::size_t>(f.group)].plane == gr.plane) continue;
            bool pos = false, neg = false;
            for (const Vec3& x : f.points) {
                const double d = gr.n.dot(x) - gr.k;
                pos = pos || d > tolerance;
                neg = neg || d < -tolerance;
            }
            split += pos && neg;
            front += pos && !neg;
            back += neg && !pos;
        }
        const std::int64_t score = 4 * split + std::abs(front - back);
        if (best < 0 || score < best_score) {
            best = g;
            best_score = score;
        }
    }
    const Group& gr = groups[static_cast<std::size_t>(best)];
    std::vector<Fragment> front, back;
    for (Fragment& f : fragments) {
        if (groups[static_cast<std::size_t>(f.group)].plane == gr.plane) continue;
        const std::size_t k = f.points.size();
        std::vector<int> s(k);
        std::vector<double> d(k);
        bool pos = false, neg = false;
        for (std::size_t i = 0; i < k; ++i) {
            d[i] = gr.n.dot(f.points[i]) - gr.k;
            // Every point with the same tolerance (original vertices too): a vertex within it of the plane is on
            // it, so that a face meeting the plane at a vertex 1e-16 away leaves no sliver behind, while the faces
            // bounding that sliver, classified the same way, are dropped with it.
            s[i] = d[i] > tolerance ? 1 : d[i] < -tolerance ? -1 : 0;
            pos = pos || s[i] > 0;
            neg = neg || s[i] < 0;
        }
        if (!pos && !neg) continue; // a sliver within the tolerance of the plane
        if (!neg) {
            front.push_back(std::move(f));
            continue;
        }
        if (!pos) {
            back.push_back(std::move(f));
            continue;
        }
        ++stats.splits;
        Fragment a{f.group, {}, {}}, b{f.group, {}, {}};
        for (std::size_t i = 0; i < k; ++i) {
            const std::size_t j = (i + 1) % k;
            if (s[i] >= 0) {
                a.points.push_back(f.points[i]);
                a.ids.push_back(f.ids[i]);
            }
            if (s[i] <= 0) {
                b.points.push_back(f.points[i]);
                b.ids.push_back(f.ids[i]);
            }
            if (s[i] * s[j] < 0) {
                const double u = d[i] / (d[i] - d[j]);
                const Vec3 x = f.points[i] + std::clamp(u, 0.0, 1.0) * (f.points[j] - f.points[i]);
                a.points.push_back(x);
                a.ids.push_back(-1);
                b.points.push_back(x);
                b.ids.push_back(-1);
            }
        }
        front.push_back(std::move(a));
        back.push_back(std::move(b));
    }
    fragments.clear();
    fragments.shrink_to_fit();
    const Index id = static_cast<Index>(nodes.size());
    nodes.push_back({best, leaf_out, leaf_in});
    Index f = leaf_out, b = leaf_in;
    if (!front.empty()) f = build(front, depth + 1);
    if (!back.empty()) b = build(back, depth + 1);
    nodes[static_cast<std::size_t>(id)].front = f;
    nodes[static_cast<std::size_t>(id)].back = b;
    return id;
}

bool BspImpl::descend(Index node, const Vec3& p, bool& near) const
{
    while (node >= 0) {
        const Node& n = nodes[static_cast<std::size_t>(node)];
        const Group& g = groups[static_cast<std::size_t>(n.group)];
        if (std::abs(g.n.dot(p) - g.k) <= 2 * tolerance) near = true;
        const int s = side(n.group, p);
        if (s > 0)
            node = n.front;
        else if (s < 0)
            node = n.back;
        else
            return descend(n.front, p, near) || descend(n.back, p, near);
    }
    return node == leaf_in;
}

bool BspImpl::exact_contains(const Vec3& p) const
{
    const Index m = static_cast<Index>(triangles.rows());
    for (Index t = 0; t < m; ++t) {
        const Vec3 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
        if (orient(a, b, c, p) == 0 && point_in_triangle_coplanar(p, a, b, c, lift_point(a, b, c))) return true;
    }
    // Parity of the crossings of a segment from p to a point outside the box; a segment through an edge or a
    // vertex, or ending on a face's plane, is replaced by one in another direction.
    const double reach = 2 * (hi - lo).norm() + (p - 0.5 * (lo + hi)).norm() + 1;
    for (int attempt = 0; attempt < 64; ++attempt) {
        const double u = 0.7390851 + 2.3999632 * attempt, v = 0.4142136 + 1.6180340 * attempt;
        const Vec3 q = p + reach * Vec3(std::cos(u) * std::sin(v), std::sin(u) * std::sin(v), std::cos(v));
        int crossings = 0;
        bool degenerate = false;
        for (Index t = 0; t < m && !degenerate; ++t) {
            const Vec3 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
            const int s1 = orient(a, b, c, p), s2 = orient(a, b, c, q);
            if (s2 == 0) degenerate = true;
            if (s1 == 0 || s1 == s2 || degenerate) continue; // p on the plane (not on the face) is no crossing
            const int t1 = orient(p, q, a, b), t2 = orient(p, q, b, c), t3 = orient(p, q, c, a);
            if ((t1 > 0 && t2 > 0 && t3 > 0) || (t1 < 0 && t2 < 0 && t3 < 0))
                ++crossings;
            else if (!((t1 > 0 || t2 > 0 || t3 > 0) && (t1 < 0 || t2 < 0 || t3 < 0)))
                degenerate = true; // through an edge or a vertex
        }
        if (!degenerate) return crossings % 2 == 1;
    }
    return false; // not reached for a valid surface: 64 segments each through an edge
}

Index BspImpl::nearest(const Vec3& p, Vec3& q, double& d2) const
{
    return tree.closest(
        p,
        [&](Index t, Vec3& x) {
            x = closest_point_on_triangle(p, corner(t, 0), corner(t, 1), corner(t, 2));
            return true;
        },
        q, d2);
}

Bsp::Bsp(const PositionsRef& vertices, const Eigen::Ref<const Triangles>& triangles, const std::string& what)
    : m_impl(std::make_unique<BspImpl>())
{
    const auto start = detail::Clock::now();
    BspImpl& b = *m_impl;
    b.vertices = vertices;
    b.triangles = triangles;
    b.check(what);
    b.lo = b.vertices.colwise().minCoeff().transpose();
    b.hi = b.vertices.colwise().maxCoeff().transpose();
    b.tolerance = 1e-10 * (b.hi - b.lo).norm();
    b.group_planes();
    const Index m = static_cast<Index>(b.triangles.rows());
    std::vector<Fragment> fragments(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        Fragment& f = fragments[static_cast<std::size_t>(t)];
        f.group = b.triangle_group[static_cast<std::size_t>(t)];
        for (int c = 0; c < 3; ++c) {
            f.points.push_back(b.corner(t, c));
            f.ids.push_back(b.triangles(t, c));
        }
    }
    b.root = b.build(fragments, 1);
    BspStats& s = b.stats;
    s.triangles = m;
    s.nodes = static_cast<Index>(b.nodes.size());
    // Leaves and their depths.
    std::int64_t path_sum = 0;
    std::vector<std::pair<Index, Index>> stack{{b.root, 0}};
    while (!stack.empty()) {
        const auto [node, depth] = stack.back();
        stack.pop_back();
        if (node < 0) {
            (node == leaf_in ? s.leaves_in : s.leaves_out)++;
            path_sum += depth;
            continue;
        }
        stack.emplace_back(b.nodes[static_cast<std::size_t>(node)].front, depth + 1);
        stack.emplace_back(b.nodes[static_cast<std::size_t>(node)].back, depth + 1);
    }
    s.mean_depth = static_cast<double>(path_sum) / std::max<Index>(1, s.leaves_in + s.leaves_out);
    s.bytes = static_cast<std::int64_t>(b.vertices.size() * sizeof(double) + b.triangles.size() * sizeof(Index) +
                                        b.nodes.size() * sizeof(Node) + b.groups.size() * sizeof(Group) +
                                        b.triangle_group.size() * sizeof(Index) +
                                        b.tree.nodes().size() * sizeof(detail::TriangleBvh::Node) +
                                        static_cast<std::size_t>(m) * (sizeof(Index) + sizeof(Vec3)));
    s.build_ms = detail::ms_since(start);
}

Bsp::~Bsp() = default;
Bsp::Bsp(Bsp&&) noexcept = default;
Bsp& Bsp::operator=(Bsp&&) noexcept = default;

bool Bsp::contains(const Eigen::Vector3d& p) const
{
    if (!p.allFinite()) return false;
    if ((p.array() < m_impl->lo.array()).any() || (p.array() > m_impl->hi.array()).any()) return false;
    bool near = false;
    const bool inside = m_impl->descend(m_impl->root, p, near);
    // Within 2 × the build tolerance of a plane on its way, a point may lie in a sliver the build could not
    // resolve (faces nearly but not exactly coplanar): the exact test over all triangles decides.
    return near ? m_impl->exact_contains(p) : inside;
}

BspHit Bsp::query(const Eigen::Vector3d& p) const
{
    BspHit hit;
    hit.inside = contains(p);
    if (!hit.inside) return hit;
    Vec3 q;
    double d2 = 0;
    hit.face = m_impl->nearest(p, q, d2);
    hit.depth = std::sqrt(d2);
    if (hit.depth > 0) {
        hit.direction = (q - p) / hit.depth;
    } else {
        const BspImpl& b = *m_impl;
        hit.direction = b.groups[static_cast<std::size_t>(b.triangle_group[static_cast<std::size_t>(hit.face)])].n;
    }
    return hit;
}

double Bsp::distance(const Eigen::Vector3d& p) const
{
    Vec3 q;
    double d2 = 0;
    m_impl->nearest(p, q, d2);
    return std::sqrt(d2);
}

const Positions& Bsp::vertices() const
{
    return m_impl->vertices;
}
const Eigen::Vector3d& Bsp::box_lo() const
{
    return m_impl->lo;
}
const Eigen::Vector3d& Bsp::box_hi() const
{
    return m_impl->hi;
}
const BspStats& Bsp::stats() const
{
    return m_impl->stats;
}

Index ObstacleSet::add(Bsp bsp)
{
    m_obstacles.push_back(std::move(bsp));
    return static_cast<Index>(m_obstacles.size()) - 1;
}

std::vector<ObstacleContact> ObstacleSet::query(const PositionsRef& positions) const
{
    std::vector<ObstacleContact> out;
    const Index n = static_cast<Index>(positions.rows());
    for (Index i = 0; i < n; ++i) {
        const Vec3 p = positions.row(i).transpose();
        if (!p.allFinite()) continue; // never inside anything
        for (Index o = 0; o < size(); ++o) {
            const Bsp& b = m_obstacles[static_cast<std::size_t>(o)];
            if ((p.array() < b.box_lo().array()).any() || (p.array() > b.box_hi().array()).any()) continue;
            const BspHit hit = b.query(p);
            if (!hit.inside) continue;
            out.push_back({i, o, hit.depth, {hit.direction.x(), hit.direction.y(), hit.direction.z()}});
        }
    }
    return out;
}

} // namespace tethash
