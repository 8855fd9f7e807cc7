// Edge-edge continuous query (include/tethash/ccd.hpp).
//
// Rounding of a corner value, per axis, M the largest coordinate magnitude of the 8 points, ε = 2^-53, to first
// order (the second-order terms are covered by the margin to 64 ε M): as in vertex_face.cpp each corner position
// x(t) = x0 + t (x1 - x0) is within 5εM; da = a1 - a0 and db = b1 - b0: ≤ 12εM; u da: ≤ 14εM; ea = a0 + u da
// (exact value on edge a, magnitude ≤ M): ≤ 20εM, eb likewise; F = ea - eb (magnitude ≤ 2M): ≤ 42εM.
#include "ccd_impl.hpp"

namespace tethash::ccd {
namespace {

/// F = ea0 + u (ea1 - ea0) - eb0 - v (eb1 - eb0) at the 8 corners of a box; rows of Motion: ea0, ea1, eb0, eb1.
struct EdgeEdgeRange {
    const detail::Motion& m;
    void operator()(const detail::Box& box, double (&f)[8][3]) const
    {
        const double ts[2] = {box.t0, box.t1}, us[2] = {box.u0, box.u1}, vs[2] = {box.v0, box.v1};
        for (int it = 0; it < 2; ++it)
            for (int k = 0; k < 3; ++k) {
                const double a0 = m.x0[0][k] + ts[it] * m.dx[0][k];
                const double a1 = m.x0[1][k] + ts[it] * m.dx[1][k];
                const double b0 = m.x0[2][k] + ts[it] * m.dx[2][k];
                const double b1 = m.x0[3][k] + ts[it] * m.dx[3][k];
                const double da = a1 - a0, db = b1 - b0;
                const double ea[2] = {a0 + us[0] * da, a0 + us[1] * da};
                const double eb[2] = {b0 + vs[0] * db, b0 + vs[1] * db};
                for (int iu = 0; iu < 2; ++iu)
                    for (int iv = 0; iv < 2; ++iv)
                        f[4 * it + 2 * iu + iv][k] = ea[iu] - eb[iv];
            }
    }
};

} // namespace

CcdResult edge_edge_ccd(const Eigen::Vector3d& ea0_0, const Eigen::Vector3d& ea1_0, const Eigen::Vector3d& eb0_0,
                        const Eigen::Vector3d& eb1_0, const Eigen::Vector3d& ea0_1, const Eigen::Vector3d& ea1_1,
                        const Eigen::Vector3d& eb0_1, const Eigen::Vector3d& eb1_1, const CcdParams& params)
{
    const detail::Points x = detail::gather({&ea0_0, &ea1_0, &eb0_0, &eb1_0, &ea0_1, &ea1_1, &eb0_1, &eb1_1});
    detail::check_query(x, params, "edge_edge_ccd");
    CcdResult r;
    if (detail::boxes_apart(x, 2)) return r;
    if (detail::never_coplanar(x)) {
        r.outcome = CcdOutcome::never_coplanar;
        return r;
    }
    detail::Motion m;
    detail::set_motion(x, m);
    detail::set_weights(x, m, 0, 1, 2, 3); // u along edge a, v along edge b
    return detail::inclusion_search(m, EdgeEdgeRange{m}, false, params);
}

} // namespace tethash::ccd
