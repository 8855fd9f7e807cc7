#pragma once
// Private to tethash::meshing: moving boundary vertices onto the surface without spoiling a tet.
#include "tethash/mesh.hpp"

#include <functional>

namespace tethash::meshing::detail {

/// Moves boundary vertices toward `target(p)` (nullopt-like: returns false when there is none),
/// one vertex at a time, as far as keeps every incident tet at ≥ kMinVolumeFraction of its lattice
/// volume and ≥ kMinDihedral degrees. Two sweeps; deterministic (vertex order).
void snap_boundary(TetMesh& mesh, const std::function<bool(const Eigen::Vector3d&, Eigen::Vector3d&)>& target,
                   double max_move);

} // namespace tethash::meshing::detail
