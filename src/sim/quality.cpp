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

double total_volume(const Model& model, const PositionsRef& x)
{
    double sum = 0;
    const Tets& tets = model.volumes.tets;
    for (Index t = 0; t < tets.rows(); ++t)
        sum += signed_volume(x, {tets(t, 0), tets(t, 1), tets(t, 2), tets(t, 3)});
    return sum;
}

std::int64_t count_far_self_penetrations(const TetMesh& mesh, const PositionsRef& start, double reach)
{
    return FarSelfPenetrations(mesh, start, reach).count(mesh.positions);
}

FarSelfPenetrations::FarSelfPenetrations(const TetMesh& mesh, const PositionsRef& start, double reach)
    : m_detector(DetectParams{.threads = 1}), m_tets(mesh.tets), m_start(start),
      m_far(reach * mean_edge_length(start, mesh.tets)), m_counted(static_cast<size_t>(mesh.num_vertices()), 0)
{
    m_detector.set_topology(mesh);
}

std::int64_t FarSelfPenetrations::count(const PositionsRef& positions)
{
    std::fill(m_counted.begin(), m_counted.end(), 0);
    std::int64_t count = 0;
    for (const Contact& c : m_detector.detect(positions)) {
        if (c.vertex_object != c.tet_object || m_counted[static_cast<size_t>(c.vertex)]) continue;
        double nearest = INFINITY;
        for (int k = 0; k < 4; ++k)
            nearest = std::min(nearest, (m_start.row(c.vertex) - m_start.row(m_tets(c.tet, k))).norm());
        if (nearest > m_far) {
            m_counted[static_cast<size_t>(c.vertex)] = 1;
            ++count;
        }
    }
    return count;
}

} // namespace tethash::sim
