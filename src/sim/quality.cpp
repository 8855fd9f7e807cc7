#include "tethash/sim/quality.hpp"

#include "tethash/detect.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tethash::sim {

std::int64_t count_inverted(const TetMesh& mesh, const PositionsRef& start)
{
    std::int64_t count = 0;
    for (Index t = 0; t < mesh.num_tets(); ++t) {
        const std::array<Index, 4> tet{mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)};
        count += (signed_volume(start, tet) > 0) != (signed_volume(mesh.positions, tet) > 0) ? 1 : 0;
    }
    return count;
}

std::int64_t count_far_self_penetrations(const TetMesh& mesh, const PositionsRef& start, double reach)
{
    Detector det(DetectParams{});
    DetectParams p;
    p.threads = 1;
    det.set_params(p);
    det.set_topology(mesh);
    const double far = reach * mean_edge_length(start, mesh.tets);
    std::vector<char> counted(static_cast<size_t>(mesh.num_vertices()), 0);
    std::int64_t count = 0;
    for (const Contact& c : det.detect(mesh.positions)) {
        if (c.vertex_object != c.tet_object || counted[static_cast<size_t>(c.vertex)]) continue;
        double nearest = INFINITY;
        for (int k = 0; k < 4; ++k)
            nearest = std::min(nearest, (start.row(c.vertex) - start.row(mesh.tets(c.tet, k))).norm());
        if (nearest > far) {
            counted[static_cast<size_t>(c.vertex)] = 1;
            ++count;
        }
    }
    return count;
}

} // namespace tethash::sim
