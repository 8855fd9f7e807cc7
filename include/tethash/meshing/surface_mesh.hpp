#pragma once
/// \file meshing/surface_mesh.hpp
/// A triangle surface: what tetrahedralize() meshes the inside of and what io::read_surface returns.
#include "tethash/mesh.hpp"

namespace tethash::meshing {

struct SurfaceMesh {
    Positions vertices;  ///< k × 3
    Triangles triangles; ///< t × 3
};

} // namespace tethash::meshing
