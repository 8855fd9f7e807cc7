#pragma once
/// \file io/medit.hpp
/// Medit .mesh (Vertices, Tetrahedra, references kept). ASCII; '#' starts a comment.
/// Errors: "FILE:LINE: expected X, found Y".
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

namespace tethash::io {

/// MeshVersionFormatted 1..4 (ASCII), Dimension 3; Vertices refs -> vertex_label, Tetrahedra refs ->
/// tet_label (1-based). Other blocks (Triangles, Edges, Corners, ...) are skipped; Triangles, Edges,
/// Quadrilaterals, Hexahedra, Prisms and Pyramids count as skipped cells.
TetMesh read_medit(const std::string& path, ReadNotes* notes = nullptr);
/// Writes MeshVersionFormatted 2 with Vertices and Tetrahedra (refs: the labels, or 0).
void write_medit(const std::string& path, const TetMesh& mesh);

} // namespace tethash::io
