#pragma once
// PLY surfaces read by tethash itself (private header; io::read_surface uses it for .ply).
#include "tethash/mesh.hpp"

#include <string>
#include <vector>

namespace tethash::io::detail {

/// Appends the vertices (x y z triples) and the faces, fanned into triangles (vertex index triples), of the
/// PLY file `path` (ASCII or binary). Throws Error naming the file and the line or byte on bad input.
void read_ply(const std::string& path, std::vector<double>& xyz, std::vector<Index>& tri);

} // namespace tethash::io::detail
