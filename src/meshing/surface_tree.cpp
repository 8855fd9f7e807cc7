#include "surface_tree.hpp"

#include "tethash/error.hpp"
#include "tethash/geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <string>

namespace tethash::meshing::detail {

void check_surface(const SurfaceMesh& s)
{
    if (s.triangles.rows() == 0) throw Error("surface has no triangles");
    const Index nv = static_cast<Index>(s.vertices.rows());
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
        for (int k = 0; k < 3; ++k)
            if (s.triangles(t, k) < 0 || s.triangles(t, k) >= nv)
                throw Error("surface triangle " + std::to_string(t) + " has vertex index " +
                            std::to_string(s.triangles(t, k)) + " out of range (0.." + std::to_string(nv - 1) + ")");
    if (!s.vertices.allFinite()) throw Error("surface has a non-finite vertex coordinate");
}

namespace {

/// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom and Strackee).
double solid_angle(const Vec3& a, const Vec3& b, const Vec3& c)
{
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    return 2.0 * std::atan2(num, den);
}

} // namespace

SurfaceTree::SurfaceTree(const SurfaceMesh& s) : m_s(s)
{
    using Node = tethash::detail::TriangleBvh::Node;
    const auto nt = static_cast<Index>(s.triangles.rows());
    m_dipoles.reserve(static_cast<std::size_t>(2 * nt / kLeaf + 2));
    m_bvh.build(
        nt,
        [&](Index t, Vec3& a, Vec3& b, Vec3& c) {
            a = vertex(t, 0);
            b = vertex(t, 1);
            c = vertex(t, 2);
        },
        kLeaf,
        [&](Index id, const Node& node) {
            m_dipoles.resize(static_cast<std::size_t>(id) + 1);
            Dipole& d = m_dipoles[static_cast<std::size_t>(id)];
            double total_area = 0;
            Vec3 weighted = Vec3::Zero();
            for (Index k = node.first; k < node.first + node.count; ++k) {
                const Index t = m_bvh.item(k);
                const Vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
                const Vec3 av = 0.5 * (b - a).cross(c - a);
                d.area += av;
                const double ar = av.norm();
                total_area += ar;
                weighted += ar * m_bvh.centre(t);
            }
            d.centre = total_area > 0 ? Vec3(weighted / total_area) : Vec3((node.lo + node.hi) / 2);
            for (Index k = node.first; k < node.first + node.count; ++k)
                for (int c = 0; c < 3; ++c)
                    d.radius = std::max(d.radius, (vertex(m_bvh.item(k), c) - d.centre).norm());
        });
}

double SurfaceTree::winding(const Vec3& q) const
{
    if (m_bvh.empty()) return 0;
    const auto& nodes = m_bvh.nodes();
    double w = 0;
    Index stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Index id = stack[--top];
        const auto& nd = nodes[static_cast<std::size_t>(id)];
        const Dipole& d = m_dipoles[static_cast<std::size_t>(id)];
        const Vec3 r = d.centre - q;
        const double dist = r.norm();
        if (dist > kBeta * d.radius) {
            w += r.dot(d.area) / (dist * dist * dist);
            continue;
        }
        if (nd.left < 0) {
            for (Index k = nd.first; k < nd.first + nd.count; ++k) {
                const Index t = m_bvh.item(k);
                w += solid_angle(vertex(t, 0) - q, vertex(t, 1) - q, vertex(t, 2) - q);
            }
        } else {
            stack[top++] = nd.left;
            stack[top++] = nd.right;
        }
    }
    return w / (4.0 * std::numbers::pi);
}

Vec3 SurfaceTree::closest(const Vec3& q) const
{
    Vec3 best = q;
    double d2 = 0;
    m_bvh.closest(
        q,
        [&](Index t, Vec3& p) {
            p = closest_point_on_triangle(q, vertex(t, 0), vertex(t, 1), vertex(t, 2));
            return true;
        },
        best, d2);
    return best;
}

} // namespace tethash::meshing::detail
