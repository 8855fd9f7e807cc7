#pragma once
/// \file io/vtu.hpp
/// VTK XML UnstructuredGrid (.vtu): ascii, base64 binary, raw appended, zlib-compressed if zlib is available.
///
/// Readers keep the tetrahedra (VTK_TETRA, type 10) in file order and skip every other cell type,
/// counting them in ReadNotes::skipped_cells. Cell arrays named "object" become tet_object, and
/// "tet_label", "label", "gmsh:physical", "medit:ref", "CellEntityIds" or "MaterialIds" become
/// tet_label (point arrays "object" / "vertex_label", "label", "medit:ref" likewise), when they hold
/// integers. Other point and cell data are ignored.
///
/// Writers store positions as Float64/double (exact round trip), tets as Int32, the user fields as
/// Float64 and the mesh's object ids and labels as Int32 arrays "object", "tet_label", "vertex_label"
/// (a user field of the same name takes precedence).
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/surface_mesh.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace tethash::io {

/// VTK XML UnstructuredGrid (.vtu): format ascii, binary (base64) or appended (raw or base64),
/// either byte order, UInt32 or UInt64 headers, vtkZLibDataCompressor (when built with zlib),
/// several Pieces (concatenated).
TetMesh read_vtu(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// Binary appended raw data (no base64), little-endian, UInt32 header (UInt64 if an array
/// exceeds 4 GiB).
void write_vtu(const std::string& path, const TetMesh& mesh, const Fields& fields = {});
/// What read_vtu_contents reads beyond the tets: the triangle cells and every data array.
struct VtuContents {
    TetMesh mesh;                             ///< as read_vtu returns it
    Triangles triangles;                      ///< the triangle cells (VTK type 5), ids into mesh.positions
    std::vector<std::int64_t> tet_cells;      ///< the file's cell index of each tet of mesh
    std::vector<std::int64_t> triangle_cells; ///< the file's cell index of each triangle
    Fields fields; ///< every point and cell array of 1 or 3 components, as Float64; cell arrays over the file's cells
};
/// read_vtu, keeping also the triangles and the data arrays (for pictures of simulation frames and of the static
/// surfaces written beside them).
VtuContents read_vtu_contents(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// A triangle surface (VTK type 5 cells) with an Int32 cell array "object" (one id per triangle): the static
/// obstacles of a simulation, written beside its frames. Binary appended, as write_vtu.
void write_vtu_surface(const std::string& path, const meshing::SurfaceMesh& surface,
                       const std::vector<Index>& triangle_object);
/// True if read_vtu can read zlib-compressed files (tethash was built with zlib).
bool vtu_zlib_supported();

} // namespace tethash::io
