#pragma once
/// \file io/cells.hpp
/// Cell files: the cells and portals of the `portals` broad phase (tethash/portals.hpp) as text, one item per line.
///
///     # a comment runs from '#' to the end of the line; blank lines are skipped
///     cell NAME XMIN YMIN ZMIN XMAX YMAX ZMAX
///     cell NAME planes NX NY NZ D  NX NY NZ D ...       # the convex cell of the half-spaces n · x <= d
///     cell NAME surface FILE                           # the convex cell a closed convex surface bounds
///     portal CELL_A CELL_B X0 Y0 Z0 X1 Y1 Z1
///     portal CELL_A CELL_B polygon X Y Z  X Y Z  X Y Z ... # a convex polygon, its corners in order
///
/// A cell is a closed box (min < max on every axis), or a bounded convex cell with a volume given by at least 4
/// half-spaces (at most max_cell_planes) or by a closed convex triangle surface (any format `io::read_surface` reads,
/// FILE relative to the cell file's folder); it is named by a word without spaces; cells may share faces, not volume
/// (two convex cells must lie on either side of a face plane of one of them). A portal joins two cells declared above
/// it: an axis-aligned rectangle given by two opposite corners, flat on the plane of the face the two cells share
/// (X0 == X1 for a face across x) and lying within that face; or a convex planar polygon of at least 3 corners lying
/// on a face plane of each cell and within both (the tests allow 1e-9 of the coordinates' magnitude). Lengths are in
/// the scene's units. Every problem is an Error "PATH:LINE: …": an unknown keyword, a missing or extra field, a
/// number that is not finite, an inverted or flat cell, planes that leave no volume or do not close the cell, a
/// surface that is not closed or not convex, a name used twice, overlapping cells, a portal between unknown cells,
/// between cells that share no face, or off their shared face; a polygon that is not planar, not convex, without
/// area, or not on the boundary the two cells share; a file without any cell.
#include "tethash/portals.hpp"

#include <string>
#include <string_view>

namespace tethash::io {

/// The cells and portals of a cell file.
CellLayout read_cells(const std::string& path);
/// The same on text already in memory; `path` names it in messages.
CellLayout parse_cells(const std::string& path, std::string_view text);
/// The text of a cell file that reads back as `layout` exactly (numbers in their shortest exact form); a convex cell
/// is written as its planes, its box's six faces first (the same set of points).
std::string cells_text(const CellLayout& layout);

} // namespace tethash::io
