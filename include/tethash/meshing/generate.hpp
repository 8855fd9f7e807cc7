#pragma once
/// \file meshing/generate.hpp
/// Tet meshes of built-in shapes (box, bar, sphere, torus, ...), each a signed-distance function
/// meshed on the BCC lattice of tetrahedralize.hpp. Deterministic: the same parameters give the same
/// mesh bit for bit, whatever the thread count.
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <string>
#include <vector>

namespace tethash::meshing {

struct GenerateParams {
    std::string shape = "box"; ///< box, bar, sphere, torus, ... (see generate_shapes())
    int resolution = 8;        ///< lattice cells along the shape's longest extent (≥ 1)
    /// Extents of the shape's bounding box (length units). A zero vector means the shape's natural
    /// size (shape_natural_size(), e.g. 4 × 1 × 1 for "bar"). Non-uniform sizes stretch the shape.
    Eigen::Vector3d size{0.0, 0.0, 0.0};
    double scale = 1.0; ///< multiplies the size (natural or given); > 0
    bool snap = true;   ///< move boundary vertices onto the surface
};

/// A shape generate() knows.
struct ShapeInfo {
    std::string name;
    std::string description;
    Eigen::Vector3d natural_size; ///< bounding-box extents at scale 1
};
/// Every shape generate() knows, in a fixed order.
const std::vector<ShapeInfo>& shape_catalog();
/// Names of the shapes generate() knows.
std::vector<std::string> generate_shapes();
/// Bounding-box extents of `shape` at scale 1; throws Error for an unknown shape.
Eigen::Vector3d shape_natural_size(const std::string& shape);
/// The mesh of a shape, centred at the origin (its bounding box is about -size/2..size/2).
/// Throws Error for an unknown shape, resolution < 1 or > 1000, or a size/scale ≤ 0.
TetMesh generate(const GenerateParams& params);

} // namespace tethash::meshing
