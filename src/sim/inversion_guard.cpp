#include "inversion_guard.hpp"

#include "vertex_stencils.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>

namespace tethash::sim {

namespace {

using std::size_t;

/// W = 6 V of the tet with corners c in positions x (stride 4).
double tet_w(const double* x, const std::int32_t* c)
{
    const Eigen::Vector3d p0(x + 4 * static_cast<size_t>(c[0]));
    return (Eigen::Vector3d(x + 4 * static_cast<size_t>(c[1])) - p0)
        .dot((Eigen::Vector3d(x + 4 * static_cast<size_t>(c[2])) - p0)
                 .cross(Eigen::Vector3d(x + 4 * static_cast<size_t>(c[3])) - p0));
}

/// ∇ of W (tet_w) with respect to corner a.
Eigen::Vector3d volume_gradient(const double* x, const std::int32_t* c, int a)
{
    auto p = [&](int k) { return Eigen::Vector3d(x + 4 * static_cast<size_t>(c[k])); };
    const Eigen::Vector3d e1 = p(1) - p(0), e2 = p(2) - p(0), e3 = p(3) - p(0);
    switch (a) {
    case 1:
        return e2.cross(e3);
    case 2:
        return e3.cross(e1);
    case 3:
        return e1.cross(e2);
    default:
        return -(e2.cross(e3) + e3.cross(e1) + e1.cross(e2));
    }
}

} // namespace

InversionGuard::InversionGuard(const Model& model)
    : m_model(model), m_tets_at(detail::incidences(model.volumes.tets, model.mass.size(), false))
{
    m_corners.resize(static_cast<size_t>(model.volumes.tets.rows()) * 4);
    for (Index t = 0; t < model.volumes.tets.rows(); ++t)
        for (int a = 0; a < 4; ++a)
            m_corners[static_cast<size_t>(4 * t + a)] = static_cast<std::int32_t>(model.volumes.tets(t, a));
}

void InversionGuard::start_without_inversions(double* x, const Positions& start)
{
    const Model& model = m_model;
    const size_t nt = m_corners.size() / 4;
    m_bad.clear();
    for (size_t t = 0; t < nt; ++t)
        if (!model.volumes.sliver[t] && !(tet_w(x, &m_corners[4 * t]) > 0))
            m_bad.push_back(static_cast<std::int32_t>(t));
    if (m_bad.empty()) return;
    m_taken.assign(model.mass.size(), 0);
    while (!m_bad.empty()) {
        const size_t t = static_cast<size_t>(m_bad.back());
        m_bad.pop_back();
        if (model.volumes.sliver[t] || tet_w(x, &m_corners[4 * t]) > 0) continue;
        for (int a = 0; a < 4; ++a) {
            const size_t v = static_cast<size_t>(m_corners[4 * t + static_cast<size_t>(a)]);
            if (m_taken[v] || model.fixed[v]) continue;
            m_taken[v] = 1;
            for (Index r = 0; r < 3; ++r)
                x[4 * v + static_cast<size_t>(r)] = start(static_cast<Index>(v), r);
            for (std::int32_t e = m_tets_at.start[v]; e < m_tets_at.start[v + 1]; ++e)
                m_bad.push_back(m_tets_at.entries[static_cast<size_t>(e)]);
        }
    }
}

double InversionGuard::corner_move_allowed(const double* x, std::size_t v, const double d[3], bool hold_slivers) const
{
    const Model& model = m_model;
    double t_max = std::numeric_limits<double>::infinity();
    for (std::int32_t e = m_tets_at.start[v]; e < m_tets_at.start[v + 1]; ++e) {
        const size_t t = static_cast<size_t>(m_tets_at.entries[static_cast<size_t>(e)]);
        if (!hold_slivers && model.volumes.sliver[t]) continue;
        const std::int32_t* c = &m_corners[4 * t];
        int a = 0;
        while (static_cast<size_t>(c[a]) != v)
            ++a;
        const Eigen::Vector3d g = volume_gradient(x, c, a);
        const double w = tet_w(x, c), nd = g.dot(Eigen::Vector3d(d[0], d[1], d[2]));
        if (!(w > 0) || !(nd < 0)) continue;
        const double floor = 0.5 * std::min(w, detail::guard_fraction * 6.0 * model.volumes.rest[t]);
        t_max = std::min(t_max, (w - floor) / -nd);
    }
    return std::min(1.0, 0.9 * t_max);
}

void InversionGuard::restore_after_step(double* x, const std::vector<std::int32_t>& inverted)
{
    m_bad.assign(inverted.begin(), inverted.end());
    restore_inverted(x, restore_move_edges, true);
}

void InversionGuard::restore_in_substep(double* x)
{
    m_bad.clear();
    const size_t nt = m_corners.size() / 4;
    for (size_t t = 0; t < nt; ++t)
        if (!(tet_w(x, &m_corners[4 * t]) > 0)) m_bad.push_back(static_cast<std::int32_t>(t));
    restore_inverted(x, std::numeric_limits<double>::infinity(), false);
}

void InversionGuard::restore_inverted(double* x, double longest_move, bool hold_slivers)
{
    const Model& model = m_model;
    for (int pass = 0; pass < restore_passes && !m_bad.empty(); ++pass) {
        bool inverted = false;
        for (const std::int32_t t : m_bad) {
            const std::int32_t* c = &m_corners[4 * static_cast<size_t>(t)];
            const double w = tet_w(x, c);
            if (w > 0) continue;
            inverted = true;
            // One corner moves (its other tets guarded as in the sweeps): the one with the shortest way back.
            const double target = detail::guard_fraction * 6.0 * model.volumes.rest[static_cast<size_t>(t)];
            int order[4] = {0, 1, 2, 3};
            Eigen::Vector3d g[4];
            for (int a = 0; a < 4; ++a)
                g[a] = volume_gradient(x, c, a);
            std::sort(order, order + 4, [&](int p, int q) { return g[p].squaredNorm() > g[q].squaredNorm(); });
            for (const int a : order) {
                const size_t v = static_cast<size_t>(c[a]);
                if (model.fixed[v] || !(g[a].squaredNorm() > 0)) continue;
                Eigen::Vector3d step = (target - w) / g[a].squaredNorm() * g[a];
                const double longest =
                    longest_move * model.object_mean_edge[static_cast<size_t>(model.vertex_object[v])];
                if (step.norm() > longest) step *= longest / step.norm();
                const double d[3] = {step.x(), step.y(), step.z()};
                const double f = corner_move_allowed(x, v, d, hold_slivers);
                for (size_t r = 0; r < 3; ++r)
                    x[4 * v + r] += f * d[r];
                if (tet_w(x, c) > 0) break;
            }
        }
        if (!inverted) return;
    }
}

} // namespace tethash::sim
