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

namespace tethash::io {

/// VTK XML UnstructuredGrid (.vtu): format ascii, binary (base64) or appended (raw or base64),
/// either byte order, UInt32 or UInt64 headers, vtkZLibDataCompressor (when built with zlib),
/// several Pieces (concatenated).
TetMesh read_vtu(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// Binary appended raw data (no base64), little-endian, UInt32 header (UInt64 if an array
/// exceeds 4 GiB).
void write_vtu(const std::string& path, const TetMesh& mesh, const Fields& fields = {});
/// True if read_vtu can read zlib-compressed files (tethash was built with zlib).
bool vtu_zlib_supported();

} // namespace tethash::io
