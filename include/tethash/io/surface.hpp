#pragma once
/// \file io/surface.hpp
/// Triangle surfaces through assimp (OBJ, STL, PLY, OFF, glTF, ...): import for obstacles and for
/// tetrahedralization, export of a tet mesh's boundary. Without assimp these throw Error saying so.
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/surface_mesh.hpp"

namespace tethash::io {

using meshing::SurfaceMesh;

/// True when tethash was built with assimp.
bool have_assimp();
/// All meshes of the file merged into one triangle soup with shared vertices joined (assimp's JoinIdenticalVertices).
SurfaceMesh read_surface(const std::string& path);
/// Format from the extension (.obj .ply .stl .gltf .glb).
void write_surface(const std::string& path, const SurfaceMesh& surface);
/// True if `path` has a surface extension.
bool is_surface_path(const std::string& path);

} // namespace tethash::io
