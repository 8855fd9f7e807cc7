#pragma once
// Private to tethash, shared by core (penetration depth) and meshing (winding numbers, snapping): an
// axis-aligned bounding-box tree over triangles at fixed positions. Median split along the widest extent
// of the triangle centres, ties broken by triangle index, so the tree depends on the input only.
// Depth is bounded by the median split (log2 of the triangle count); the traversal stacks hold 128.
#include "tethash/mesh.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <numeric>
#include <vector>

namespace tethash::detail {

class TriangleBvh {
  public:
    using Vec3 = Eigen::Vector3d;

    struct Node {
        Vec3 lo, hi;                 ///< bounding box of the node's triangles
        Index left = -1, right = -1; ///< children (inner node) or -1 (leaf)
        Index first = 0, count = 0;  ///< the node's triangles: item(first) .. item(first + count - 1)
    };

    /// Builds the tree over triangles 0 .. n-1; `corners(t, a, b, c)` sets the corners of triangle t.
    /// Nodes with at most `leaf_size` triangles are leaves. `on_node(id, node)`, called for every node
    /// before its range is split, may gather per-node data (nodes() has `id` + 1 entries at that time;
    /// its children come later).
    template <class Corners, class OnNode> void build(Index n, Corners&& corners, Index leaf_size, OnNode&& on_node)
    {
        m_nodes.clear();
        m_order.resize(static_cast<std::size_t>(n));
        std::iota(m_order.begin(), m_order.end(), Index(0));
        m_centre.resize(static_cast<std::size_t>(n));
        std::vector<Vec3> lo(static_cast<std::size_t>(n)), hi(static_cast<std::size_t>(n));
        for (Index t = 0; t < n; ++t) {
            Vec3 a, b, c;
            corners(t, a, b, c);
            const auto k = static_cast<std::size_t>(t);
            lo[k] = a.cwiseMin(b).cwiseMin(c);
            hi[k] = a.cwiseMax(b).cwiseMax(c);
            m_centre[k] = (a + b + c) / 3.0;
        }
        if (n > 0) build_node(0, n, lo, hi, leaf_size, on_node);
    }
    template <class Corners> void build(Index n, Corners&& corners, Index leaf_size)
    {
        build(n, corners, leaf_size, [](Index, const Node&) {});
    }

    /// Recomputes every node's box (and every triangle's centre) from `corners(t, a, b, c)` at new positions,
    /// keeping the tree's shape: the triangles of each node stay the same. A node's box is exactly the
    /// union of its triangles' corner boxes, as after build. Nodes come before their children, so one
    /// backward pass suffices.
    template <class Corners> void refit(Corners&& corners)
    {
        for (auto id = static_cast<std::ptrdiff_t>(m_nodes.size()) - 1; id >= 0; --id) {
            Node& node = m_nodes[static_cast<std::size_t>(id)];
            if (node.left >= 0) {
                const Node& l = m_nodes[static_cast<std::size_t>(node.left)];
                const Node& r = m_nodes[static_cast<std::size_t>(node.right)];
                node.lo = l.lo.cwiseMin(r.lo);
                node.hi = l.hi.cwiseMax(r.hi);
                continue;
            }
            Vec3 blo = Vec3::Constant(std::numeric_limits<double>::infinity()), bhi = -blo;
            for (Index k = node.first; k < node.first + node.count; ++k) {
                const Index t = item(k);
                Vec3 a, b, c;
                corners(t, a, b, c);
                blo = blo.cwiseMin(a.cwiseMin(b).cwiseMin(c));
                bhi = bhi.cwiseMax(a.cwiseMax(b).cwiseMax(c));
                m_centre[static_cast<std::size_t>(t)] = (a + b + c) / 3.0;
            }
            node.lo = blo;
            node.hi = bhi;
        }
    }

    /// Sum of the surface areas of all node boxes divided by the root box's (the expected number of nodes
    /// a random ray through the root visits): grows as a refitted tree's boxes come to overlap.
    double cost() const
    {
        if (m_nodes.empty()) return 0;
        auto area = [](const Node& n) {
            const Vec3 e = (n.hi - n.lo).cwiseMax(Vec3::Zero());
            return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
        };
        double sum = 0;
        for (const Node& n : m_nodes)
            sum += area(n);
        const double root = area(m_nodes.front());
        return root > 0 ? sum / root : 0;
    }

    bool empty() const { return m_nodes.empty(); }
    const std::vector<Node>& nodes() const { return m_nodes; }
    /// The triangle at position k of the tree's order (a node holds positions first .. first + count - 1).
    Index item(Index k) const { return m_order[static_cast<std::size_t>(k)]; }
    /// Centre (mean of the corners) of triangle t.
    const Vec3& centre(Index t) const { return m_centre[static_cast<std::size_t>(t)]; }

    /// Squared distance from p to the box of `node` (0 inside).
    static double squared_distance(const Node& node, const Vec3& p)
    {
        return (node.lo - p).cwiseMax(p - node.hi).cwiseMax(Vec3::Zero()).squaredNorm();
    }

    /// Visits every triangle of a leaf whose box meets the box lo..hi.
    template <class Visit> void for_box(const Vec3& lo, const Vec3& hi, Visit&& visit) const
    {
        if (m_nodes.empty()) return;
        Index stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top) {
            const Node& n = m_nodes[static_cast<std::size_t>(stack[--top])];
            // Plain comparisons, all evaluated: cheaper than branching on each.
            if ((n.lo[0] > hi[0]) | (n.lo[1] > hi[1]) | (n.lo[2] > hi[2]) | (n.hi[0] < lo[0]) | (n.hi[1] < lo[1]) |
                (n.hi[2] < lo[2]))
                continue;
            if (n.left < 0) {
                for (Index k = n.first; k < n.first + n.count; ++k)
                    visit(item(k));
            } else if (top < 126) {
                stack[top++] = n.left;
                stack[top++] = n.right;
            }
        }
    }

    /// The closest point to p over the triangles for which `point_of(t, q)` sets a point q (and returns
    /// true; false skips the triangle). Returns the triangle (-1 if none) and sets best_point and its
    /// squared distance best_d2. Nearer children first, so most of the tree is pruned. The answer is the least
    /// (distance², triangle) over all accepted triangles, whatever the tree's shape (built or refitted): a node
    /// is skipped only when its box, widened by far more than the rounding of a computed closest point, is
    /// farther than the best so far.
    template <class PointOf> Index closest(const Vec3& p, PointOf&& point_of, Vec3& best_point, double& best_d2) const
    {
        best_d2 = std::numeric_limits<double>::infinity();
        Index best = -1;
        if (m_nodes.empty()) return best;
        const double scale = std::max(
            {m_nodes[0].lo.cwiseAbs().maxCoeff(), m_nodes[0].hi.cwiseAbs().maxCoeff(), p.cwiseAbs().maxCoeff()});
        const double h = 1e-9 * scale + std::numeric_limits<double>::min();
        auto lower = [&](const Node& n) {
            const double d2 =
                ((n.lo.array() - h) - p.array()).max(p.array() - (n.hi.array() + h)).max(0.0).matrix().squaredNorm();
            return d2 * (1 - 1e-12);
        };
        Index stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top) {
            const Node& n = m_nodes[static_cast<std::size_t>(stack[--top])];
            if (lower(n) > best_d2) continue;
            if (n.left < 0) {
                for (Index k = n.first; k < n.first + n.count; ++k) {
                    const Index t = item(k);
                    Vec3 q;
                    if (!point_of(t, q)) continue;
                    const double d2 = (q - p).squaredNorm();
                    if (d2 < best_d2 || (d2 == best_d2 && t < best)) {
                        best_d2 = d2;
                        best_point = q;
                        best = t;
                    }
                }
            } else if (top < 126) {
                // Nearer child last so that it is popped first.
                const Node& l = m_nodes[static_cast<std::size_t>(n.left)];
                const Node& r = m_nodes[static_cast<std::size_t>(n.right)];
                if (squared_distance(l, p) < squared_distance(r, p)) {
                    stack[top++] = n.right;
                    stack[top++] = n.left;
                } else {
                    stack[top++] = n.left;
                    stack[top++] = n.right;
                }
            }
        }
        return best;
    }

  private:
    template <class OnNode>
    Index build_node(Index first, Index count, const std::vector<Vec3>& lo, const std::vector<Vec3>& hi,
                     Index leaf_size, OnNode& on_node)
    {
        const Index id = static_cast<Index>(m_nodes.size());
        m_nodes.emplace_back();
        Vec3 blo = Vec3::Constant(std::numeric_limits<double>::infinity()), bhi = -blo;
        Vec3 clo = blo, chi = bhi;
        for (Index k = first; k < first + count; ++k) {
            const auto t = static_cast<std::size_t>(item(k));
            blo = blo.cwiseMin(lo[t]);
            bhi = bhi.cwiseMax(hi[t]);
            clo = clo.cwiseMin(m_centre[t]);
            chi = chi.cwiseMax(m_centre[t]);
        }
        Node& node = m_nodes[static_cast<std::size_t>(id)];
        node.lo = blo;
        node.hi = bhi;
        node.first = first;
        node.count = count;
        on_node(id, static_cast<const Node&>(node));
        if (count <= leaf_size) return id;
        int axis = 0;
        (chi - clo).maxCoeff(&axis);
        const Index mid = first + count / 2;
        std::nth_element(m_order.begin() + first, m_order.begin() + mid, m_order.begin() + first + count,
                         [&](Index a, Index b) {
                             const double ca = m_centre[static_cast<std::size_t>(a)][axis];
                             const double cb = m_centre[static_cast<std::size_t>(b)][axis];
                             return ca < cb || (ca == cb && a < b);
                         });
        const Index l = build_node(first, mid - first, lo, hi, leaf_size, on_node);
        const Index r = build_node(mid, first + count - mid, lo, hi, leaf_size, on_node);
        m_nodes[static_cast<std::size_t>(id)].left = l;
        m_nodes[static_cast<std::size_t>(id)].right = r;
        return id;
    }

    std::vector<Node> m_nodes;
    std::vector<Index> m_order;
    std::vector<Vec3> m_centre;
};

} // namespace tethash::detail
