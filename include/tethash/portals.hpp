#pragma once
/// \file portals.hpp
/// The cells and portals of the `portals` broad phase (DetectParams::method = Method::portals, docs/partitions.md):
/// the world divided into convex cells (rooms) joined by portals (doors, windows) on the faces they share.
///
/// Cells are closed convex polyhedra whose interiors do not overlap (they may share faces, edges and corners, and
/// need not cover the scene: what lies outside every cell is the "outside" cell of the method): axis-aligned boxes,
/// or boxes cut by half-spaces (convex cells given as planes or as a closed convex surface). Portals are
/// axis-aligned rectangles lying on the face two box cells share (a flat box: lo == hi on the face's axis), or convex
/// polygons on the boundary two cells share. Cells and portals only decide how the work is divided: the method
/// returns the oracle's contacts for any layout, with or without portals, and for a scene lying wholly outside its
/// cells. The text format that describes them is read by `tethash/io/cells.hpp`.

#include "tethash/bsp.hpp"
#include "tethash/mesh.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tethash {

/// The closed half-space n · x ≤ d.
struct CellPlane {
    double n[3] = {0, 0, 0};
    double d = 0;
};

/// A convex cell: the closed box [lo, hi] (lo < hi on every axis), cut by the closed half-spaces `planes` when there
/// are any (a box cell has none). A cell of planes has its bounding box as [lo, hi] (convex_cell sets it).
struct PortalCell {
    std::string name;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    std::vector<CellPlane> planes;
};

/// A portal between cells a and b (indices into CellLayout::cells, a ≠ b). Without `polygon`: the closed rectangle
/// [lo, hi] with lo[axis] == hi[axis] on the plane of the face the two (box) cells share, lying within that shared
/// face. With `polygon`: a convex planar polygon (its corners in order, at least 3) lying on the boundary both cells
/// share; [lo, hi] is then its bounding box (polygon_portal sets it).
struct Portal {
    Index a = 0, b = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    std::vector<std::array<double, 3>> polygon;
};

struct CellLayout {
    std::vector<PortalCell> cells;
    std::vector<Portal> portals;
};

/// The most planes a convex cell may have (the checks meet every three of them).
inline constexpr std::size_t max_cell_planes = 64;

/// The convex cell {x : n · x ≤ d for every plane} with its bounding box as [lo, hi]. Throws Error naming the cell
/// when a plane is not finite or has a zero normal, or when the cell is unbounded or has no interior.
PortalCell convex_cell(const std::string& name, const std::vector<CellPlane>& planes);
/// The convex cell bounded by a closed convex triangle surface (vertices k × 3, triangles t × 3, either orientation):
/// the half-spaces of its faces. Throws Error naming the cell when the surface is not closed, or not convex (a vertex
/// beyond a face's plane), or when it has more than max_cell_planes distinct face planes.
PortalCell surface_cell(const std::string& name, const PositionsRef& vertices,
                        const Eigen::Ref<const Triangles>& triangles);
/// The portal of the convex polygon `corners` (in order) between cells a and b, its bounding box set.
Portal polygon_portal(Index a, Index b, std::vector<std::array<double, 3>> corners);
/// The corners of a cell (the vertices of the polytope: its box cut by its planes).
std::vector<std::array<double, 3>> cell_corners(const PortalCell& cell);

/// Checks cell k against cells 0..k-1: finite, lo < hi on every axis, a name not used before, planes bounding a
/// cell with an interior, no overlap of interiors. Throws Error naming the cell (and the other cell).
void check_cell(const CellLayout& layout, std::size_t k);
/// Checks portal k: known cells a ≠ b. A rectangle between box cells: the cells share a face, the rectangle is
/// finite, flat on that face's plane and lies within the shared face. A polygon (or a rectangle touching a cell of
/// planes): at least 3 finite corners, planar, convex, of positive area, on a boundary plane of each cell and within
/// both cells. Throws Error naming the portal's cells.
void check_portal(const CellLayout& layout, std::size_t k);
/// Every cell and portal checked, in order. Throws Error on the first problem.
void check_cell_layout(const CellLayout& layout);

/// `n[0] × n[1] × n[2]` cells of equal size over the box [lo, hi] with every shared face a portal: the layout the
/// method makes for itself when it is given none (named "x,y,z" by grid coordinate), and a quick way to write one.
CellLayout grid_cell_layout(const double lo[3], const double hi[3], const int n[3]);

/// The cells of the free space around static obstacles (closed surfaces: the walls of a building as BSP obstacles),
/// for the `portals` method when no cell description is given. The box made of `[lo, hi]` (when given) and the
/// obstacles' boxes is cut on each axis at the obstacles' vertex coordinates (all of them when there are at most
/// `max_cuts` on the axis, else `max_cuts` of them evenly chosen in their sorted list); each piece of the grid is
/// "solid" when its centre lies in an obstacle (the first one, by index), else free; the pieces of one kind (free, or
/// one obstacle's) are merged greedily into boxes, seeded from the largest pieces first and grown both ways along x,
/// then y, then z. The free boxes (cells "free0", "free1",
/// ...) are joined by a portal on every face two of them share; the solid ones ("solid0", ...) have no portal. With
/// axis-aligned obstacles the free cells are exactly the space between them (the rooms, split where a wall's corner
/// or a door's edge cuts them) and the portals exactly the openings between them (the doors); with other obstacles they
/// approximate it. The method is exact with any layout: the cells only divide the work. Throws Error when there is
/// no obstacle or max_cuts < 2.
CellLayout cells_from_obstacles(const ObstacleSet& obstacles, const double* lo = nullptr, const double* hi = nullptr,
                                int max_cuts = 48);

/// What a query of CellWalls did.
struct WallStats {
    std::int64_t vertices = 0; ///< finite vertices queried
    std::int64_t tests = 0;    ///< (vertex, obstacle) pairs looked at: the walls of the vertex's cell
    std::int64_t all = 0;      ///< the pairs a query of every obstacle looks at (vertices × obstacles)
    std::int64_t outside = 0;  ///< vertices in no cell (tested against the outside's walls)
};

class CellWallsImpl;

/// The object-world part of cells and portals: each obstacle is a wall of the cells its closed box meets, and each
/// vertex is tested only against the walls of its cell (the first cell holding it, as the `portals` broad phase
/// assigns it); a vertex in no cell against the obstacles that do not lie within one cell. A vertex inside an
/// obstacle lies in that obstacle's box and in its own cell, so the box meets the cell: the answer is
/// ObstacleSet::query's, exactly.
class CellWalls {
  public:
    /// The layout must pass check_cell_layout; `obstacles` must outlive this object and keep its obstacles.
    CellWalls(const CellLayout& layout, const ObstacleSet& obstacles);
    ~CellWalls();
    CellWalls(CellWalls&&) noexcept;
    CellWalls& operator=(CellWalls&&) noexcept;
    CellWalls(const CellWalls&) = delete;
    CellWalls& operator=(const CellWalls&) = delete;

    /// The walls of cell c, ascending; c == number of cells: the walls of the outside.
    const std::vector<Index>& walls(Index cell) const;
    /// obstacles.query(positions): the vertices inside (or on) some obstacle, sorted by (vertex, obstacle).
    std::vector<ObstacleContact> query(const PositionsRef& positions, WallStats* stats = nullptr) const;

  private:
    std::unique_ptr<CellWallsImpl> m_impl;
};

} // namespace tethash
