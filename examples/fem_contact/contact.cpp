#include "contact.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <unordered_map>

namespace fem {

namespace {
/// The FEM's position vector seen by tethash as n × 3 row-major: a map, no copy.
Eigen::Map<const tethash::Positions> as_positions(const Vec& x)
{
    return {x.data(), x.size() / 3, 3};
}
} // namespace

ContactModule::ContactModule(const Mesh& mesh, const ContactSettings& settings) : m_settings(settings)
{
    tethash::DetectParams params;
    params.threads = settings.threads;
    params.skin_mode = tethash::DetectParams::SkinMode::factor_of_cell_size;
    params.skin = settings.skin;
    m_detector.set_params(params);
    const Eigen::Map<const tethash::Tets> tets(mesh.tets.data(), mesh.elements(), 4);
    m_nodes = mesh.nodes();
    m_tets = mesh.tets;
    m_detector.set_topology(tets, m_nodes, mesh.node_object, mesh.tet_object);
    m_penetration.set_topology(tets, m_nodes, mesh.node_object, mesh.tet_object);
    m_objects = 1 + *std::max_element(mesh.node_object.begin(), mesh.node_object.end());
}

void ContactModule::add(const Vec& x, Vec& f, Triplets* K, ContactReport& report)
{
    const auto t0 = std::chrono::steady_clock::now();
    const tethash::PositionsRef positions(as_positions(x));
    // The detector reads the FEM's own array: the reference must not have made a copy.
    if (positions.data() != x.data()) {
        std::fprintf(stderr, "fem_contact: tethash would read a copy of the positions\n");
        std::abort();
    }
    tethash::DetectStats stats;
    std::vector<tethash::Contact>& contacts = m_detector.contacts();
    m_detector.detect(positions, &stats);
    m_penetration.compute(positions, contacts);
    report.ms_tethash = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    report.reused = stats.reused != 0;

    report.contacts = report.self_contacts = 0;
    report.max_depth = report.energy = 0;
    report.force.assign(3 * static_cast<size_t>(m_objects), 0.0);
    report.pairs.clear();
    const double k = m_settings.stiffness;
    report.stiffness = k;
    // Contacts are sorted by (node, tet); a node inside several tets of one object gets one penalty (its depth and
    // direction are per node and object).
    for (size_t c = 0; c < contacts.size(); ++c) {
        const tethash::Contact& ct = contacts[c];
        bool seen = false;
        for (auto p = report.pairs.rbegin(); p != report.pairs.rend() && p->vertex == ct.vertex; ++p)
            seen = seen || p->tet_object == ct.tet_object;
        if (seen || !(ct.depth > 0)) continue;
        report.pairs.push_back(ct);
        ++report.contacts;
        if (ct.vertex_object == ct.tet_object) ++report.self_contacts;
        report.max_depth = std::max(report.max_depth, ct.depth);
        report.energy += 0.5 * k * ct.depth * ct.depth;
        // The direction of a (node, object) pair is kept from its first evaluation in the time step: the estimate
        // turns by a few degrees where a node slides across faces, which Newton cannot converge through.
        const std::int64_t key = static_cast<std::int64_t>(ct.vertex) * m_objects + ct.tet_object;
        auto [frozen, fresh] =
            m_directions.try_emplace(key, Eigen::Vector3d(ct.direction[0], ct.direction[1], ct.direction[2]));
        (void)fresh;
        const Eigen::Vector3d n = frozen->second;
        for (int r = 0; r < 3; ++r)
            report.pairs.back().direction[r] = n[r];
        // d ≈ d0 − n·δx_node + Σ bᵢ n·δx_i: gradient coefficients c (node −1, tet nodes bᵢ).
        int node[5] = {ct.vertex, 0, 0, 0, 0};
        double coef[5] = {-1, 0, 0, 0, 0};
        for (int i = 0; i < 4; ++i) {
            node[i + 1] = m_tets[4 * static_cast<size_t>(ct.tet) + static_cast<size_t>(i)];
            coef[i + 1] = ct.bary[i];
        }
        for (int a = 0; a < 5; ++a) {
            const Eigen::Vector3d fa = -k * ct.depth * coef[a] * n;
            f.segment<3>(3 * node[a]) += fa;
            const int obj = a == 0 ? ct.vertex_object : ct.tet_object;
            for (int r = 0; r < 3; ++r)
                report.force[3 * static_cast<size_t>(obj) + static_cast<size_t>(r)] += fa[r];
        }
        if (!K) continue;
        const Eigen::Matrix3d nn = k * n * n.transpose();
        for (int a = 0; a < 5; ++a)
            for (int b = 0; b < 5; ++b)
                for (int r = 0; r < 3; ++r)
                    for (int s = 0; s < 3; ++s)
                        K->emplace_back(3 * node[a] + r, 3 * node[b] + s, coef[a] * coef[b] * nn(r, s));
    }
}

std::vector<double> ContactModule::exact_depths(const Vec& x, const ContactReport& report) const
{
    return m_penetration.exact_depths(as_positions(x), report.pairs);
}

} // namespace fem
