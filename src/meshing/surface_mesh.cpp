// The boundary of a tet mesh as a triangle surface.
#include "tethash/meshing/surface_mesh.hpp"

#include <cstddef>
#include <vector>

namespace tethash::meshing {

SurfaceMesh boundary_surface(const TetMesh& mesh)
{
    mesh.check_consistency("mesh for its boundary surface");
    const Triangles faces = boundary_faces(mesh.tets);
    std::vector<Index> new_id(static_cast<std::size_t>(mesh.num_vertices()), -1);
    for (Eigen::Index i = 0; i < faces.rows(); ++i)
        for (int k = 0; k < 3; ++k)
            new_id[static_cast<std::size_t>(faces(i, k))] = 0;
    Index n = 0;
    for (auto& id : new_id)
        if (id == 0) id = n++; // increasing original index: deterministic
    SurfaceMesh s;
    s.vertices.resize(n, 3);
    for (Index v = 0; v < mesh.num_vertices(); ++v)
        if (new_id[static_cast<std::size_t>(v)] >= 0)
            s.vertices.row(new_id[static_cast<std::size_t>(v)]) = mesh.positions.row(v);
    s.triangles.resize(faces.rows(), 3);
    for (Eigen::Index i = 0; i < faces.rows(); ++i)
        for (int k = 0; k < 3; ++k)
            s.triangles(i, k) = new_id[static_cast<std::size_t>(faces(i, k))];
    return s;
}

} // namespace tethash::meshing
