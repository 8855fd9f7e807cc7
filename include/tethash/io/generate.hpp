#pragma once
/// \file io/generate.hpp
/// Tet meshes made by tethash itself: signed-distance shapes on a body-centred-cubic (BCC) lattice,
/// and closed surfaces tetrahedralized on the same lattice (no TetGen). Deterministic: the same
/// input gives the same mesh bit for bit, whatever the thread count.
///
/// The lattice: cube centres and cube corners of a (slightly per-axis stretched) cubic grid; every
/// tet joins two neighbouring cube centres and one edge of the face the two cubes share. Unsnapped,
/// every tet has dihedral angles of 60° and 90° (for an unstretched grid). A tet is kept when its
/// centroid is inside; unreferenced lattice vertices are dropped. Snapping then moves boundary
/// vertices onto the surface, one at a time, only as far as keeps every incident tet positively
/// oriented, at least a fraction of its lattice volume, and above a minimum dihedral angle.
/// All output tets have (b-a)·((c-a)×(d-a)) > 0.
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"

#include <functional>

namespace tethash::io {

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

/// Tet mesh of the inside of a signed-distance function (negative inside) over `box_min`..`box_max`.
/// `resolution` cells along the box's longest extent. The function need not be an exact distance
/// (a sign-correct implicit function with a sensible gradient works; snapping uses Newton steps).
/// Throws Error for resolution < 1 or > 1000, an empty box, or when nothing is inside.
/// `project(p, h)`, when given, is where boundary vertex p should go on a lattice of spacing h (per
/// axis), e.g. onto the edges and corners of a box (a closest-point projection would cut them off).
TetMesh tetrahedralize_sdf(
    const std::function<double(const Eigen::Vector3d&)>& sdf, const Eigen::Vector3d& box_min,
    const Eigen::Vector3d& box_max, int resolution, bool snap,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d& p, const Eigen::Vector3d& h)>& project = {});

struct TetrahedralizeParams {
    int resolution = 16; ///< lattice cells along the surface's longest bounding-box extent
    bool snap = true;    ///< move boundary vertices to the closest point of the surface
};
/// Closed (or nearly closed) surface to tets: inside test by generalized winding number (|w| > 1/2,
/// so small holes, cracks and a globally inward orientation are tolerated), BCC lattice over the
/// surface's bounding box. Throws Error for an empty surface, bad indices, or no inside found.
TetMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeParams& params);

/// Generalized winding number of `surface` at each query point (1 inside a closed outward-oriented
/// surface, 0 outside, fractional near holes). Hierarchical: triangle groups farther than twice their
/// radius count as dipoles (first order), which is off by up to a few per cent; that is far from the
/// 1/2 that decides inside, and triangles near the point are summed exactly.
std::vector<double> winding_numbers(const SurfaceMesh& surface, const std::vector<Eigen::Vector3d>& points);

} // namespace tethash::io
