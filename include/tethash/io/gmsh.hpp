#pragma once
/// \file io/gmsh.hpp
/// Gmsh .msh 2.2 and 4.1, ASCII and binary (either byte order). Element type 4 (4-node tet) is kept,
/// in file order; other element types are skipped with a count in ReadNotes. All nodes are kept in file
/// order; node tags may be sparse or unordered (they are mapped to 0-based indices).
/// Labels (TetMesh::tet_label): 4.1 -> the first physical tag of the tet block's entity (from
/// $Entities) if it has one, else the entity tag; 2.2 -> the element's first (physical) tag, or its
/// second (elementary) tag where the physical tag is 0 or absent. Object ids are not read.
/// Sections the reader does not need ($PhysicalNames, $NodeData, $Periodic, $Surface, any other) are
/// skipped up to their $End line. Errors: "FILE:LINE: expected X, found Y", or "FILE: byte OFFSET: ..."
/// inside binary data.
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

namespace tethash::io {

TetMesh read_msh(const std::string& path, ReadNotes* notes = nullptr, const ReadOptions& options = {});
/// Writes MSH 4.1 (ASCII unless `binary`; binary is little-endian with 8-byte size_t) through
/// write_atomically. One volume entity per (object id, label) pair, numbered 1, 2, ... in order of first
/// appearance, with the label as its physical tag when the mesh has labels; node and element tags are
/// index + 1 and the file order is the index order, so reading the file back gives the same arrays.
void write_msh(const std::string& path, const TetMesh& mesh, bool binary = false);

} // namespace tethash::io
