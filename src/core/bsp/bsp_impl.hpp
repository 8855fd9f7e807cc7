#pragma once
// The solid-leaf BSP tree behind Bsp (private header): its nodes, plane groups and fragments, and the exact
// triangle tests that both the surface check (bsp_check.cpp) and the closed query (bsp.cpp) use
// (bsp_geometry.cpp).
#include "../triangle_bvh.hpp"
#include "tethash/bsp.hpp"
#include "tethash/predicates.hpp"

#include <Eigen/Geometry>

#include <array>
#include <string>
#include <vector>

namespace tethash::bsp_detail {

using Vec3 = Eigen::Vector3d;

constexpr Index leaf_out = -1;
constexpr Index leaf_in = -2;

struct Group {
    Index rep = -1;   ///< triangle whose vertices define the plane (largest area of the group)
    Index plane = -1; ///< geometric plane (both facings share it)
    Vec3 n{0, 0, 0};  ///< unit normal (floating point), outwards
    double k = 0;     ///< n · x on the plane
};

struct Fragment {
    Index group = -1;
    std::vector<Vec3> points;
    std::vector<Index> ids; ///< original vertex id of each point, -1 for a clipped point
};

struct Node {
    Index group = -1; ///< the plane: the group's representative triangle, front = outwards
    Index front = leaf_out;
    Index back = leaf_in;
};

/// "(a, b)": an edge in messages.
std::string edge_text(Index a, Index b);

/// The exact sign of orient3d(a, b, c, d).
inline int orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
{
    return predicates::orient3d(a.data(), b.data(), c.data(), d.data()).sign;
}

// ---- exact triangle intersection tests (closed sets): bsp_geometry.cpp

/// In-plane orientation of (x, y, z) seen from the lift point w (off their plane).
int orient2(const Vec3& x, const Vec3& y, const Vec3& z, const Vec3& w);
/// Coplanar segments pq and rs (w lifted off their plane) meet.
bool segments_meet_coplanar(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, const Vec3& w);
/// p in the closed triangle (a, b, c) of its plane (w lifted off it).
bool point_in_triangle_coplanar(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& w);
/// A point off the plane of (a, b, c) (a non-degenerate triangle).
Vec3 lift_point(const Vec3& a, const Vec3& b, const Vec3& c);
/// The closed segment pq meets the closed triangle (a, b, c).
bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c);
/// The closed triangles u and v meet.
bool triangles_meet(const std::array<Vec3, 3>& u, const std::array<Vec3, 3>& v);
/// Triangles (v, a, b) and (v, c, d) sharing only v: true if they meet anywhere else.
bool triangles_meet_beyond_vertex(const Vec3& v, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

} // namespace tethash::bsp_detail

namespace tethash {

using bsp_detail::Fragment;
using bsp_detail::Group;
using bsp_detail::leaf_in;
using bsp_detail::leaf_out;
using bsp_detail::Node;
using bsp_detail::orient;
using bsp_detail::Vec3;

class BspImpl {
  public:
    Positions vertices;
    Triangles triangles;
    std::vector<Group> groups;
    std::vector<Index> triangle_group;
    std::vector<Node> nodes;
    Index root = leaf_out;
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    double tolerance = 0;
    BspStats stats;
    detail::TriangleBvh tree;

    Vec3 vertex(Index i) const { return vertices.row(i).transpose(); }
    Vec3 corner(Index t, int c) const { return vertex(triangles(t, c)); }

    int side(Index group, const Vec3& p) const
    {
        const Index t = groups[static_cast<std::size_t>(group)].rep;
        return orient(corner(t, 0), corner(t, 1), corner(t, 2), p);
    }

    void check(const std::string& what);
    void group_planes();
    Index build(std::vector<Fragment>& fragments, Index depth);
    bool descend(Index node, const Vec3& p, bool& near) const;
    bool exact_contains(const Vec3& p) const;
    Index nearest(const Vec3& p, Vec3& q, double& d2) const;
};

} // namespace tethash
