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

InsideOtherObjects::InsideOtherObjects(const TetMesh& mesh)
    : m_detector(DetectParams{.threads = 1}), m_counted(static_cast<size_t>(mesh.num_vertices()), 0)
{
    // Self-contacts are not looked for: an object's own tets cost nothing beyond the hash's stage 1.
    Index objects = 1;
    for (const std::vector<Index>* ids : {&mesh.vertex_object, &mesh.tet_object})
        if (!ids->empty()) objects = std::max(objects, *std::max_element(ids->begin(), ids->end()) + 1);
    std::vector<ObjectOptions> options(static_cast<size_t>(objects));
    for (ObjectOptions& o : options)
        o.self_collision = false;
    m_detector.set_topology(mesh, options);
}

std::int64_t InsideOtherObjects::count(const PositionsRef& positions)
{
    std::fill(m_counted.begin(), m_counted.end(), 0);
    std::int64_t count = 0;
    for (const Contact& c : m_detector.detect(positions)) {
        if (c.vertex_object == c.tet_object || m_counted[static_cast<size_t>(c.vertex)]) continue;
        m_counted[static_cast<size_t>(c.vertex)] = 1;
        ++count;
    }
    return count;
}

} // namespace tethash::sim
