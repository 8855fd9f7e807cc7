#pragma once
// Private to tethash::meshing: repair of the set of lattice tets kept as inside.
#include <array>
#include <cstdint>
#include <vector>

namespace tethash::meshing::detail {

/// Makes the boundary of the kept set a manifold: adds every lattice tet around a boundary edge used
/// by more than two boundary faces, and around a boundary vertex whose boundary faces form more than
/// one fan (two parts touching at a vertex), until none is left (or a few rounds passed). `keep` is
/// indexed like `all`.
void repair_nonmanifold(const std::vector<std::array<std::int64_t, 4>>& all, std::vector<char>& keep);

} // namespace tethash::meshing::detail
