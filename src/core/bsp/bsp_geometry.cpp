// Exact tests on triangles of a closed surface (closed sets), for the BSP tree's surface check and its closed
// query: orientation in a plane seen from a lifted point, segments, points and triangles meeting.
#include "bsp_impl.hpp"

namespace tethash::bsp_detail {

std::string edge_text(Index a, Index b)
{
    // Appended piece by piece: g++ 12 warns (-Wrestrict, a false positive) on "(" + std::to_string(a) + ….
    std::string s = "(";
    s += std::to_string(a);
    s += ", ";
    s += std::to_string(b);
    s += ")";
    return s;
}

/// In-plane orientation of (x, y, z) seen from the lift point w (off their plane).
int orient2(const Vec3& x, const Vec3& y, const Vec3& z, const Vec3& w)
{
    return orient(x, y, z, w);
}

bool segments_meet_coplanar(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, const Vec3& w)
{
    const int o1 = orient2(p, q, r, w), o2 = orient2(p, q, s, w);
    const int o3 = orient2(r, s, p, w), o4 = orient2(r, s, q, w);
    if (o1 * o2 < 0 && o3 * o4 < 0) return true;
    auto on = [](const Vec3& a, const Vec3& b, const Vec3& x) {
        return (x.array() >= a.cwiseMin(b).array()).all() && (x.array() <= a.cwiseMax(b).array()).all();
    };
    if (o1 == 0 && on(p, q, r)) return true;
    if (o2 == 0 && on(p, q, s)) return true;
    if (o3 == 0 && on(r, s, p)) return true;
    if (o4 == 0 && on(r, s, q)) return true;
    return false;
}

bool point_in_triangle_coplanar(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& w)
{
    const int s = orient2(a, b, c, w);
    const int s1 = orient2(a, b, p, w) * s, s2 = orient2(b, c, p, w) * s, s3 = orient2(c, a, p, w) * s;
    return s1 >= 0 && s2 >= 0 && s3 >= 0;
}

/// A point off the plane of (a, b, c) (a non-degenerate triangle).
Vec3 lift_point(const Vec3& a, const Vec3& b, const Vec3& c)
{
    const Vec3 n = (b - a).cross(c - a);
    const double size = std::max({(b - a).norm(), (c - a).norm(), 1e-300});
    Vec3 w = a + n.normalized() * size;
    if (orient(a, b, c, w) == 0) w = a + n.normalized() * (2 * size) + Vec3(size, 0, 0);
    return w;
}

bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c)
{
    const int s1 = orient(a, b, c, p), s2 = orient(a, b, c, q);
    if (s1 * s2 > 0) return false;
    if (s1 == 0 && s2 == 0) {
        const Vec3 w = lift_point(a, b, c);
        return point_in_triangle_coplanar(p, a, b, c, w) || point_in_triangle_coplanar(q, a, b, c, w) ||
               segments_meet_coplanar(p, q, a, b, w) || segments_meet_coplanar(p, q, b, c, w) ||
               segments_meet_coplanar(p, q, c, a, w);
    }
    const int t1 = orient(p, q, a, b), t2 = orient(p, q, b, c), t3 = orient(p, q, c, a);
    return !((t1 > 0 || t2 > 0 || t3 > 0) && (t1 < 0 || t2 < 0 || t3 < 0));
}

bool triangles_meet(const std::array<Vec3, 3>& u, const std::array<Vec3, 3>& v)
{
    for (int i = 0; i < 3; ++i)
        if (segment_meets_triangle(u[i], u[(i + 1) % 3], v[0], v[1], v[2])) return true;
    for (int i = 0; i < 3; ++i)
        if (segment_meets_triangle(v[i], v[(i + 1) % 3], u[0], u[1], u[2])) return true;
    return false;
}

/// Triangles (v, a, b) and (v, c, d) sharing only v: true if they meet anywhere else.
bool triangles_meet_beyond_vertex(const Vec3& v, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
{
    if (segment_meets_triangle(a, b, v, c, d) || segment_meets_triangle(c, d, v, a, b)) return true;
    // An edge from v lying in the other triangle's plane and pointing into its corner at v.
    auto edge_into = [&](const Vec3& x, const Vec3& p, const Vec3& q) {
        if (orient(v, p, q, x) != 0) return false;
        const Vec3 w = lift_point(v, p, q);
        const int s = orient2(v, p, q, w);
        return orient2(v, p, x, w) * s >= 0 && orient2(v, x, q, w) * s >= 0;
    };
    return edge_into(a, c, d) || edge_into(b, c, d) || edge_into(c, a, b) || edge_into(d, a, b);
}

} // namespace tethash::bsp_detail
