#pragma once
/// \file meshing/surface_mesh.hpp
/// A triangle surface: what tetrahedralize() meshes the inside of and what io::read_surface returns.
#include "tethash/mesh.hpp"

namespace tethash::meshing {

struct SurfaceMesh {
    Positions vertices;  ///< k × 3
    Triangles triangles; ///< t × 3
};

/// The outward boundary of `mesh` as a surface (vertices compacted, kept in increasing original index).
SurfaceMesh boundary_surface(const TetMesh& mesh);

} // namespace tethash::meshing
