#pragma once
// Private to tethash: the boundary edges of a set of boundary triangles (each triangle's three edges, (i < j),
// sorted and unique). Shared by continuous detection and the edge-face contacts.
#include "tethash/mesh.hpp"

#include <algorithm>
#include <array>
#include <vector>

namespace tethash::detail {

inline Edges edges_of_faces(const Triangles& faces)
{
    std::vector<std::array<Index, 2>> edges;
    edges.reserve(static_cast<std::size_t>(3 * faces.rows()));
    for (Eigen::Index f = 0; f < faces.rows(); ++f)
        for (int c = 0; c < 3; ++c) {
            const Index i = faces(f, c), j = faces(f, (c + 1) % 3);
            edges.push_back({std::min(i, j), std::max(i, j)});
        }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    Edges out(static_cast<Eigen::Index>(edges.size()), 2);
    for (std::size_t e = 0; e < edges.size(); ++e) {
        out(static_cast<Eigen::Index>(e), 0) = edges[e][0];
        out(static_cast<Eigen::Index>(e), 1) = edges[e][1];
    }
    return out;
}

} // namespace tethash::detail
