#pragma once
/// \file portals.hpp
/// The cells and portals of the `portals` broad phase (DetectParams::method = Method::portals, docs/partitions.md):
/// the world divided into convex cells (rooms) joined by portals (doors, windows) on the faces they share.
///
/// Cells are closed axis-aligned boxes whose interiors do not overlap (they may share faces, edges and corners, and
/// need not cover the scene: what lies outside every cell is the "outside" cell of the method). Portals are
/// axis-aligned rectangles lying on the face two cells share (a flat box: lo == hi on the face's axis). Cells and
/// portals only decide how the work is divided: the method returns the oracle's contacts for any layout, with or
/// without portals, and for a scene lying wholly outside its cells. The text format that describes them is read by
/// `tethash/io/cells.hpp`.

#include "tethash/mesh.hpp"

#include <string>
#include <vector>

namespace tethash {

/// A convex cell: the closed box [lo, hi] (lo < hi on every axis).
struct PortalCell {
    std::string name;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};

/// A portal between cells a and b (indices into CellLayout::cells, a ≠ b): the closed rectangle [lo, hi] with
/// lo[axis] == hi[axis] on the plane of the face the two cells share, lying within that shared face.
struct Portal {
    Index a = 0, b = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};

struct CellLayout {
    std::vector<PortalCell> cells;
    std::vector<Portal> portals;
};

/// Checks cell k against cells 0..k-1: finite, lo < hi on every axis, a name not used before, no overlap of
/// interiors. Throws Error naming the cell (and the other cell).
void check_cell(const CellLayout& layout, std::size_t k);
/// Checks portal k: known cells a ≠ b that share a face, finite, flat on that face's plane and lying within the
/// shared face. Throws Error naming the portal's cells.
void check_portal(const CellLayout& layout, std::size_t k);
/// Every cell and portal checked, in order. Throws Error on the first problem.
void check_cell_layout(const CellLayout& layout);

/// `n[0] × n[1] × n[2]` cells of equal size over the box [lo, hi] with every shared face a portal: the layout the
/// method makes for itself when it is given none (named "x,y,z" by grid coordinate), and a quick way to write one.
CellLayout grid_cell_layout(const double lo[3], const double hi[3], const int n[3]);

} // namespace tethash
