#pragma once
/// \file io/vtk_legacy.hpp
/// VTK legacy .vtk UNSTRUCTURED_GRID, ASCII and BINARY (big-endian).
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

/// Legacy .vtk UNSTRUCTURED_GRID, versions 1.0 to 5.1 (both the classic CELLS layout and the
/// OFFSETS/CONNECTIVITY layout of 5.x), ASCII or BINARY (big-endian), float or double points.
TetMesh read_vtk(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// Legacy .vtk version 4.2 (classic CELLS layout, read by every VTK/ParaView version);
/// BINARY (big-endian) unless `binary` is false. Point/cell fields go into FIELD blocks.
void write_vtk(const std::string& path, const TetMesh& mesh, const Fields& fields = {}, bool binary = true);

} // namespace tethash::io
