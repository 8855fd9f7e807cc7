#pragma once
// Private to tethash::meshing: a bounding-volume hierarchy over a surface's triangles for
// generalized winding numbers (far groups as dipoles) and closest points.
#include "tethash/geometry.hpp"
#include "tethash/meshing/surface_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

namespace tethash::meshing::detail {

using Vec3 = Eigen::Vector3d;

/// Throws Error for a surface without triangles, with a vertex index out of range or a non-finite vertex.
void check_surface(const SurfaceMesh& s);

// ---- surfaces: bounding-volume hierarchy for winding numbers and closest points -------------

class SurfaceTree {
  public:
    explicit SurfaceTree(const SurfaceMesh& s) : m_s(s)
    {
        const auto nt = static_cast<std::size_t>(s.triangles.rows());
        m_order.resize(nt);
        m_centroid.resize(nt);
        for (std::size_t t = 0; t < nt; ++t) {
            m_order[t] = static_cast<int>(t);
            m_centroid[t] = (vertex(t, 0) + vertex(t, 1) + vertex(t, 2)) / 3.0;
        }
        m_nodes.reserve(2 * nt / kLeaf + 2);
        if (nt > 0) build(0, static_cast<int>(nt));
    }

    /// Generalized winding number at q.
    double winding(const Vec3& q) const
    {
        double w = 0;
        int stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& nd = m_nodes[static_cast<std::size_t>(stack[--top])];
            const Vec3 r = nd.centre - q;
            const double dist = r.norm();
            if (dist > kBeta * nd.radius) {
                w += r.dot(nd.area) / (dist * dist * dist);
                continue;
            }
            if (nd.left < 0) {
                for (int i = nd.begin; i < nd.end; ++i) {
                    const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
                    w += solid_angle(vertex(t, 0) - q, vertex(t, 1) - q, vertex(t, 2) - q);
                }
            } else {
                stack[top++] = nd.left;
                stack[top++] = nd.right;
            }
        }
        return w / (4.0 * std::numbers::pi);
    }

    /// Closest point of the surface to q.
    Vec3 closest(const Vec3& q) const
    {
        double best = std::numeric_limits<double>::infinity();
        Vec3 best_p = q;
        int stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& nd = m_nodes[static_cast<std::size_t>(stack[--top])];
            if (nd.box.squaredExteriorDistance(q) >= best) continue;
            if (nd.left < 0) {
                for (int i = nd.begin; i < nd.end; ++i) {
                    const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
                    const Vec3 c = closest_point_on_triangle(q, vertex(t, 0), vertex(t, 1), vertex(t, 2));
                    const double d2 = (c - q).squaredNorm();
                    if (d2 < best) {
                        best = d2;
                        best_p = c;
                    }
                }
            } else {
                const Node& l = m_nodes[static_cast<std::size_t>(nd.left)];
                const Node& r = m_nodes[static_cast<std::size_t>(nd.right)];
                // Visit the nearer child first (pushed last).
                if (l.box.squaredExteriorDistance(q) < r.box.squaredExteriorDistance(q)) {
                    stack[top++] = nd.right;
                    stack[top++] = nd.left;
                } else {
                    stack[top++] = nd.left;
                    stack[top++] = nd.right;
                }
            }
        }
        return best_p;
    }

  private:
    static constexpr int kLeaf = 8;
    static constexpr double kBeta = 2.0; ///< far field when distance > kBeta × node radius

    struct Node {
        Eigen::AlignedBox3d box;
        Vec3 centre = Vec3::Zero(); ///< area-weighted centroid of the node's triangles
        Vec3 area = Vec3::Zero();   ///< sum of area vectors (½ (b-a)×(c-a))
        double radius = 0;          ///< max distance from centre to a triangle vertex
        int left = -1, right = -1, begin = 0, end = 0;
    };

    Vec3 vertex(std::size_t t, int k) const
    {
        return m_s.vertices.row(m_s.triangles(static_cast<Eigen::Index>(t), k)).transpose();
    }

    int build(int begin, int end)
    {
        const int id = static_cast<int>(m_nodes.size());
        m_nodes.emplace_back();
        Node nd;
        nd.begin = begin;
        nd.end = end;
        Eigen::AlignedBox3d cbox;
        double total_area = 0;
        Vec3 weighted = Vec3::Zero();
        for (int i = begin; i < end; ++i) {
            const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
            const Vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
            nd.box.extend(a);
            nd.box.extend(b);
            nd.box.extend(c);
            cbox.extend(m_centroid[t]);
            const Vec3 av = 0.5 * (b - a).cross(c - a);
            nd.area += av;
            const double ar = av.norm();
            total_area += ar;
            weighted += ar * m_centroid[t];
        }
        nd.centre = total_area > 0 ? Vec3(weighted / total_area) : nd.box.center();
        for (int i = begin; i < end; ++i) {
            const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
            for (int k = 0; k < 3; ++k)
                nd.radius = std::max(nd.radius, (vertex(t, k) - nd.centre).norm());
        }
        if (end - begin > kLeaf) {
            int axis = 0;
            cbox.sizes().maxCoeff(&axis);
            const int mid = (begin + end) / 2;
            std::nth_element(m_order.begin() + begin, m_order.begin() + mid, m_order.begin() + end, [&](int x, int y) {
                const double cx = m_centroid[static_cast<std::size_t>(x)][axis];
                const double cy = m_centroid[static_cast<std::size_t>(y)][axis];
                return cx < cy || (cx == cy && x < y);
            });
            nd.left = build(begin, mid);
            nd.right = build(mid, end);
        }
        m_nodes[static_cast<std::size_t>(id)] = nd;
        return id;
    }

    /// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom and Strackee).
    static double solid_angle(const Vec3& a, const Vec3& b, const Vec3& c)
    {
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double num = a.dot(b.cross(c));
        const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        return 2.0 * std::atan2(num, den);
    }

    const SurfaceMesh& m_s;
    std::vector<Node> m_nodes;
    std::vector<int> m_order;
    std::vector<Vec3> m_centroid;
};

} // namespace tethash::meshing::detail
