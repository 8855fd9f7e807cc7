#pragma once
/// \file geometry.hpp
/// Small geometric queries shared by the core (penetration depth) and the mesh tools (tetrahedralization).

#include <Eigen/Core>

namespace tethash {

/// Closest point to `p` on the closed triangle (a, b, c), by the Voronoi regions of its vertices and edges
/// (Ericson, Real-Time Collision Detection, 5.1.5). A degenerate (zero-area) triangle gives a vertex or a point
/// of an edge, never NaN.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

} // namespace tethash
