#pragma once
// Private to tethash::meshing: a bounding-volume hierarchy over a surface's triangles for
// generalized winding numbers (far groups as dipoles) and closest points.
#include "core/triangle_bvh.hpp"
#include "tethash/meshing/surface_mesh.hpp"

#include <vector>

namespace tethash::meshing::detail {

using Vec3 = Eigen::Vector3d;

/// Throws Error for a surface without triangles, with a vertex index out of range or a non-finite vertex.
void check_surface(const SurfaceMesh& s);

// ---- surfaces: bounding-volume hierarchy for winding numbers and closest points -------------

/// A surface's triangles in the shared triangle tree (core/triangle_bvh.hpp), with each node's dipole
/// (area-weighted centre, summed area vector, radius) for the far field of the winding number.
class SurfaceTree {
  public:
    explicit SurfaceTree(const SurfaceMesh& s);

    /// Generalized winding number at q.
    double winding(const Vec3& q) const;
    /// Closest point of the surface to q.
    Vec3 closest(const Vec3& q) const;

  private:
    static constexpr Index kLeaf = 8;
    static constexpr double kBeta = 2.0; ///< far field when distance > kBeta × node radius

    struct Dipole {
        Vec3 centre = Vec3::Zero(); ///< area-weighted centroid of the node's triangles
        Vec3 area = Vec3::Zero();   ///< sum of area vectors (½ (b-a)×(c-a))
        double radius = 0;          ///< max distance from centre to a triangle vertex
    };

    Vec3 vertex(Index t, int k) const { return m_s.vertices.row(m_s.triangles(t, k)).transpose(); }

    const SurfaceMesh& m_s;
    tethash::detail::TriangleBvh m_bvh;
    std::vector<Dipole> m_dipoles; ///< one per node of m_bvh
};

} // namespace tethash::meshing::detail
