#pragma once
/// \file meshing/tetrahedralize.hpp
/// Tet meshes of an implicit inside on a body-centred-cubic (BCC) lattice (no TetGen): the inside of a
/// signed-distance function, or of a closed surface. Deterministic: the same input gives the same mesh
/// bit for bit, whatever the thread count.
///
/// The lattice: cube centres and cube corners of a (slightly per-axis stretched) cubic grid; every
/// tet joins two neighbouring cube centres and one edge of the face the two cubes share. Unsnapped,
/// every tet has dihedral angles of 60° and 90° (for an unstretched grid). A tet is kept when its
/// centroid is inside; unreferenced lattice vertices are dropped. Snapping then moves boundary
/// vertices onto the surface, one at a time, only as far as keeps every incident tet positively
/// oriented, at least a fraction of its lattice volume, and above a minimum dihedral angle.
/// All output tets have (b-a)·((c-a)×(d-a)) > 0.
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"
#include "tethash/meshing/surface_mesh.hpp"

#include <functional>

namespace tethash::meshing {

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

} // namespace tethash::meshing
