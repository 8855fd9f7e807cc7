#pragma once
/// \file io/tetgen.hpp
/// TetGen .node + .ele pairs (0- or 1-based, attributes and boundary markers). ASCII; '#' starts a
/// comment. Errors: "FILE:LINE: expected X, found Y".
#include "tethash/error.hpp"
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

} // namespace tethash::io
