#pragma once
/// \file quality.hpp
/// What a simulated body must not end up with, measured against its start: inverted tets and vertices folded
/// through distant parts of their own body. Used by the tests, the stability sweep of `tethash study` and the
/// simulation benchmark, so that all three count the same thing.
#include "tethash/mesh.hpp"

#include <cstdint>

namespace tethash::sim {

/// Tets of `mesh` whose signed volume at `mesh.positions` has the other sign than at `start` (same topology).
std::int64_t count_inverted(const TetMesh& mesh, const PositionsRef& start);

/// Distinct vertices lying inside a tet of their own object (exact detector) whose nearest corner of that tet was
/// more than `reach` mean edges away at `start`: a fold through a distant part of the body, not a local overlap.
/// (A Simulation keeps no separate rest state: pass the positions it started from.)
std::int64_t count_far_self_penetrations(const TetMesh& mesh, const PositionsRef& start, double reach = 3.0);

} // namespace tethash::sim
