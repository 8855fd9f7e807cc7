#pragma once
/// \file io/tetgen.hpp
/// TetGen .node + .ele pairs (0- or 1-based, attributes and boundary markers), Medit .mesh (Vertices,
/// Tetrahedra, references kept) and Vega .veg (*VERTICES, *ELEMENTS TET; other sections skipped).
/// All are ASCII; '#' starts a comment. Errors: "FILE:LINE: expected X, found Y".
#include "tethash/io/mesh_io.hpp"

namespace tethash::io {

/// `path` may name either the .node or the .ele file; the other is found beside it. The first node
/// index (0 or 1) sets the numbering of both files, as in TetGen; indices must be consecutive. Short
/// headers take TetGen's defaults (dimension 3, no attributes, no markers, 4 nodes per tet).
/// The .node boundary marker -> vertex_label; the first .ele attribute -> tet_label when all its values
/// are integers (else a note). 10-node tets are read as their first 4 nodes (the corners), with a note.
TetMesh read_tetgen(const std::string& path, ReadNotes* notes = nullptr);
/// Writes NAME.node and NAME.ele (1-based; tet_label as one attribute, vertex_label as markers).
void write_tetgen(const std::string& path, const TetMesh& mesh);

/// MeshVersionFormatted 1..4 (ASCII), Dimension 3; Vertices refs -> vertex_label, Tetrahedra refs ->
/// tet_label (1-based). Other blocks (Triangles, Edges, Corners, ...) are skipped; Triangles, Edges,
/// Quadrilaterals, Hexahedra, Prisms and Pyramids count as skipped cells.
TetMesh read_medit(const std::string& path, ReadNotes* notes = nullptr);
/// Writes MeshVersionFormatted 2 with Vertices and Tetrahedra (refs: the labels, or 0).
void write_medit(const std::string& path, const TetMesh& mesh);

/// *VERTICES ("n 3 0 0", lines "id x y z", ids 1..n) and *ELEMENTS with type TET ("m 4 0", 1-based);
/// other sections are skipped; *INCLUDE and element types other than TET are errors. No labels.
TetMesh read_veg(const std::string& path, ReadNotes* notes = nullptr);

} // namespace tethash::io
