#pragma once
// Private to tethash::io: the Gmsh element types (number of nodes, name for notes).
#include <cstdint>
#include <string>

namespace tethash::io::detail {

/// Nodes per element of a Gmsh element type, 0 if the type is unknown here.
int gmsh_nodes_per_element(std::int64_t type);
/// Name of a Gmsh element type for notes ("3-node triangle"), "unknown element" if the type is unknown.
std::string gmsh_element_name(std::int64_t type);

} // namespace tethash::io::detail
