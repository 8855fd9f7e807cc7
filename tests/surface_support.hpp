#pragma once
// Surfaces for the surface, tetrahedralizer and winding-number tests.
#include "tethash/io/surface.hpp"
#include "tethash/mesh.hpp"
#include "tethash/meshing/generate.hpp"

#include <Eigen/Geometry>

namespace tethash::test {

/// The outward boundary of the generated sphere (diameter 1) at `resolution`.
inline meshing::SurfaceMesh sphere_surface(int resolution)
{
    meshing::GenerateParams p;
    p.shape = "sphere";
    p.resolution = resolution;
    return meshing::boundary_surface(meshing::generate(p));
}

/// Enclosed volume by the divergence theorem (positive for outward-oriented triangles).
inline double enclosed_volume(const meshing::SurfaceMesh& s)
{
    double v = 0;
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
        const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0)), b = s.vertices.row(s.triangles(t, 1)),
                              c = s.vertices.row(s.triangles(t, 2));
        v += a.dot(b.cross(c)) / 6.0;
    }
    return v;
}

/// Total volume of a tet mesh.
inline double volume(const TetMesh& m)
{
    return volume_stats(m.positions, m.tets).total;
}

} // namespace tethash::test
