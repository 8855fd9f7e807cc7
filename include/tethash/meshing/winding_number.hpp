#pragma once
/// \file meshing/winding_number.hpp
/// Generalized winding numbers of a triangle surface: the inside test of tetrahedralize().
#include "tethash/error.hpp"
#include "tethash/meshing/surface_mesh.hpp"

#include <vector>

namespace tethash::meshing {

/// Generalized winding number of `surface` at each query point (1 inside a closed outward-oriented
/// surface, 0 outside, fractional near holes). Hierarchical: triangle groups farther than twice their
/// radius count as dipoles (first order), which is off by up to a few per cent; that is far from the
/// 1/2 that decides inside, and triangles near the point are summed exactly.
/// Throws Error for a surface without triangles, with bad indices or non-finite vertices.
std::vector<double> winding_numbers(const SurfaceMesh& surface, const std::vector<Eigen::Vector3d>& points);

} // namespace tethash::meshing
