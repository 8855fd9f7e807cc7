#pragma once
// Convex cells (private header): the half-spaces of a cell (its box's faces, then its planes), the corners of an
// intersection of half-spaces, and the separation of two cells (convex_cells.cpp).
#include "tethash/portals.hpp"

#include <array>
#include <vector>

namespace tethash::detail {

/// The six faces of c's box (x lo, x hi, y lo, ...) and then c's planes.
std::vector<CellPlane> all_planes(const PortalCell& c);
double plane_norm(const CellPlane& p);
/// n · x − d: ≤ 0 in the half-space.
double plane_value(const CellPlane& p, const double* x);
/// The points where three of the planes meet (independent normals) lying in every half-space within eps · |n|.
std::vector<std::array<double, 3>> polytope_corners(const std::vector<CellPlane>& planes, double eps);
/// The largest magnitude of c's box: coordinates and extents.
double magnitude(const PortalCell& c);
/// x in every half-space of c within eps · |n|.
bool contains_near(const PortalCell& c, const double* x, double eps);
/// A face plane of a or of b has the other cell's corners on or beyond it (within eps · |n|): the interiors do not
/// overlap.
bool separated(const PortalCell& a, const std::vector<std::array<double, 3>>& a_corners, const PortalCell& b,
               const std::vector<std::array<double, 3>>& b_corners, double eps);

} // namespace tethash::detail
