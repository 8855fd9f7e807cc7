#pragma once
/// \file io/cells.hpp
/// Cell files: the cells and portals of the `portals` broad phase (tethash/portals.hpp) as text, one item per line.
///
///     # a comment runs from '#' to the end of the line; blank lines are skipped
///     cell NAME XMIN YMIN ZMIN XMAX YMAX ZMAX
///     portal CELL_A CELL_B X0 Y0 Z0 X1 Y1 Z1
///
/// A cell is a closed box (min < max on every axis) named by a word without spaces; cells may share faces, not
/// volume. A portal joins two cells declared above it: an axis-aligned rectangle given by two opposite corners, flat
/// on the plane of the face the two cells share (X0 == X1 for a face across x) and lying within that face. Lengths
/// are in the scene's units. Every problem is an Error "PATH:LINE: …": an unknown keyword, a missing or extra field,
/// a number that is not finite, an inverted or flat cell, a name used twice, overlapping cells, a portal between
/// unknown cells, between cells that share no face, or off their shared face; a file without any cell.
#include "tethash/portals.hpp"

#include <string>
#include <string_view>

namespace tethash::io {

/// The cells and portals of a cell file.
CellLayout read_cells(const std::string& path);
/// The same on text already in memory; `path` names it in messages.
CellLayout parse_cells(const std::string& path, std::string_view text);
/// The text of a cell file that reads back as `layout` exactly (numbers in their shortest exact form).
std::string cells_text(const CellLayout& layout);

} // namespace tethash::io
