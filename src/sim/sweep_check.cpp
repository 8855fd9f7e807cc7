#include "sweep_check.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tethash::sim {

void SweepCheck::setup(const TetMesh& mesh, const Model& model, const std::vector<ObjectOptions>& options,
                       const std::vector<std::pair<Index, Index>>& object_vertices, double local_edges, double margin)
{
    m_detector.set_topology(mesh.tets, mesh.num_vertices());
    m_object = model.vertex_object;
    const size_t objects = object_vertices.size();
    m_local_sq.assign(objects, 0.0);
    m_margin.assign(objects, 0.0);
    m_self.assign(objects, 1);
    m_static.assign(objects, 0);
    m_range = object_vertices;
    for (size_t o = 0; o < objects; ++o) {
        const double edge = o < model.object_mean_edge.size() ? model.object_mean_edge[o] : 0.0;
        m_local_sq[o] = local_edges * edge * local_edges * edge;
        m_margin[o] = margin * edge;
        if (o < options.size()) {
            m_self[o] = options[o].self_collision ? 1 : 0;
            m_static[o] = options[o].is_static ? 1 : 0;
        }
    }
    m_moving.assign(static_cast<size_t>(mesh.num_vertices()), 0);
    // The contacts' locality rule, applied in the detector's broad phase: most pairs its grid meets are neighbours.
    m_detector.set_locality(mesh.rest(), m_object, m_local_sq);
}

bool SweepCheck::crossed(const Positions& x0, const Positions& x1, const std::vector<std::pair<Index, Index>>& watched,
                         int threads)
{
    using Vec3 = Eigen::Vector3d;
    using Mat3 = Eigen::Matrix3d;
    const size_t objects = m_range.size();
    // Per object: the affine motion that fits its vertices' displacements best (d ≈ A (x0 − centre) + b, least
    // squares) and its swept box. Under an affine motion a gap g becomes g + t A g, so a pair whose gap at the start
    // is at least the margin m meets within the step only if what is left of its vertices' displacements (residuals)
    // adds up to (1 − |A|) m or more: a vertex is marked moving when its residual exceeds half that. Objects whose
    // boxes, grown by their margins, meet another's are near: their vertices are marked by their displacement itself.
    std::vector<Vec3> lo(objects), hi(objects);
    std::vector<Mat3> affine(objects, Mat3::Zero());
    std::vector<Vec3> shift(objects, Vec3::Zero()), centre(objects, Vec3::Zero());
    std::vector<double> reach(objects, 0.0);
    std::vector<char> near(objects, 0);
    for (size_t o = 0; o < objects; ++o) {
        const auto [first, count] = m_range[o];
        lo[o] = Vec3::Constant(std::numeric_limits<double>::infinity());
        hi[o] = -lo[o];
        if (count == 0) continue;
        for (Index i = first; i < first + count; ++i) {
            const Vec3 a = x0.row(i).transpose(), b = x1.row(i).transpose();
            centre[o] += a;
            shift[o] += b - a;
            lo[o] = lo[o].cwiseMin(a).cwiseMin(b);
            hi[o] = hi[o].cwiseMax(a).cwiseMax(b);
        }
        centre[o] /= count;
        shift[o] /= count;
        Mat3 rr = Mat3::Zero(), rd = Mat3::Zero();
        for (Index i = first; i < first + count; ++i) {
            const Vec3 r = x0.row(i).transpose() - centre[o], d = (x1.row(i) - x0.row(i)).transpose();
            rr += r * r.transpose();
            rd += r * d.transpose();
        }
        const Eigen::LDLT<Mat3> ldlt(rr);
        if (ldlt.info() == Eigen::Success && ldlt.isPositive() && rr.determinant() > 0) {
            const Mat3 at = ldlt.solve(rd);
            if (at.allFinite()) affine[o] = at.transpose();
        }
        const double shrink = 1 - affine[o].norm(); // |A| ≤ its Frobenius norm
        reach[o] = shrink > 0 ? 0.5 * shrink * m_margin[o] : 0.0;
        lo[o].array() -= m_margin[o];
        hi[o].array() += m_margin[o];
    }
    for (size_t o = 0; o < objects; ++o)
        for (size_t p = o + 1; p < objects; ++p) {
            if ((m_static[o] && m_static[p]) || (lo[o].array() > hi[p].array()).any() ||
                (lo[p].array() > hi[o].array()).any())
                continue;
            near[o] = near[p] = 1;
        }
    m_moving_count = 0;
    for (size_t o = 0; o < objects; ++o) {
        const auto [first, count] = m_range[o];
        const double r2 = reach[o] * reach[o], m2 = 0.25 * m_margin[o] * m_margin[o];
        for (Index i = first; i < first + count; ++i) {
            const Vec3 d = (x1.row(i) - x0.row(i)).transpose();
            const Vec3 residual = d - affine[o] * (x0.row(i).transpose() - centre[o]) - shift[o];
            const bool moving =
                !m_static[o] && ((m_self[o] && residual.squaredNorm() >= r2) || (near[o] && d.squaredNorm() >= m2));
            m_moving[static_cast<size_t>(i)] = moving ? 1 : 0;
            m_moving_count += moving;
        }
    }
    m_impacts = 0;
    if (m_moving_count == 0) return false;

    const Triangles& faces = m_detector.faces();
    const Edges& edges = m_detector.edges();
    auto watched_against = [&](Index v, Index object) {
        return std::binary_search(watched.begin(), watched.end(), std::pair(v, object));
    };
    // Whether the pair of vertex lists a and b (of objects oa and ob) is one the check looks at.
    auto far_pair = [&](const Index* a, int na, const Index* b, int nb) {
        const Index oa = m_object[static_cast<size_t>(a[0])], ob = m_object[static_cast<size_t>(b[0])];
        const auto ua = static_cast<size_t>(oa), ub = static_cast<size_t>(ob);
        if (oa == ob) {
            if (!m_self[ua]) return false; // (local pairs are left out by the detector: set_locality)
        } else if (m_static[ua] && m_static[ub]) {
            return false;
        }
        for (int i = 0; i < na; ++i)
            if (watched_against(a[i], ob)) return false;
        for (int k = 0; k < nb; ++k)
            if (watched_against(b[k], oa)) return false;
        return true;
    };
    const ccd::ContinuousDetector::PairFilter keep = [&](ccd::ContinuousKind kind, Index a, Index b) {
        if (kind == ccd::ContinuousKind::vertex_face) {
            const Index f[3] = {faces(b, 0), faces(b, 1), faces(b, 2)};
            return far_pair(&a, 1, f, 3);
        }
        const Index e[2] = {edges(a, 0), edges(a, 1)}, g[2] = {edges(b, 0), edges(b, 1)};
        return far_pair(e, 2, g, 2);
    };
    ccd::ContinuousParams params;
    params.threads = threads;
    params.first_only = true; // whether, not which
    const ccd::ContinuousResult& r = m_detector.detect(x0, x1, params, m_moving, keep);
    m_impacts = static_cast<std::int64_t>(r.contacts.size());
    return m_impacts > 0;
}

} // namespace tethash::sim
