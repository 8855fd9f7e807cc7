// Vertex-triangle continuous query (include/tethash/ccd.hpp).
//
// Rounding of a corner value, per axis, M the largest coordinate magnitude of the 8 points, ε = 2^-53, to first
// order (the second-order terms are covered by the margin to 64 ε M): a displacement d = x1 - x0 is one rounding of
// a value of magnitude ≤ 2M (error ≤ 2εM); x(t) = x0 + t d, t in [0, 1] exact, adds ≤ 2εM (the product) and ≤ εM
// (the sum, whose exact value lies between x0 and x1): error ≤ 5εM, for p(t), a(t), b(t), c(t). Then
// d0 = p - a and e1 = b - a, e2 = c - a: ≤ 10εM propagated + 2εM rounding = 12εM each; u e1, v e2 (u, v in
// [0, 1] exact): ≤ 14εM; d0 - u e1 (exact value p - ((1 - u) a + u b), magnitude ≤ 2M): ≤ 28εM; minus v e2
// (magnitude ≤ 4M): ≤ 46εM.
#include "ccd_impl.hpp"

namespace tethash::ccd {
namespace {

/// F = p(t) - a(t) - u (b(t) - a(t)) - v (c(t) - a(t)) at the 8 corners of a box; rows of Motion: p, a, b, c.
struct VertexFaceRange {
    const detail::Motion& m;
    void operator()(const detail::Box& box, double (&f)[8][3]) const
    {
        const double ts[2] = {box.t0, box.t1}, us[2] = {box.u0, box.u1}, vs[2] = {box.v0, box.v1};
        for (int it = 0; it < 2; ++it)
            for (int k = 0; k < 3; ++k) {
                const double p = m.x0[0][k] + ts[it] * m.dx[0][k];
                const double a = m.x0[1][k] + ts[it] * m.dx[1][k];
                const double b = m.x0[2][k] + ts[it] * m.dx[2][k];
                const double c = m.x0[3][k] + ts[it] * m.dx[3][k];
                const double d0 = p - a, e1 = b - a, e2 = c - a;
                for (int iu = 0; iu < 2; ++iu) {
                    const double du = d0 - us[iu] * e1;
                    for (int iv = 0; iv < 2; ++iv)
                        f[4 * it + 2 * iu + iv][k] = du - vs[iv] * e2;
                }
            }
    }
};

} // namespace

CcdResult vertex_face_ccd(const Eigen::Vector3d& p0, const Eigen::Vector3d& a0, const Eigen::Vector3d& b0,
                          const Eigen::Vector3d& c0, const Eigen::Vector3d& p1, const Eigen::Vector3d& a1,
                          const Eigen::Vector3d& b1, const Eigen::Vector3d& c1, const CcdParams& params)
{
    const detail::Points x = detail::gather({&p0, &a0, &b0, &c0, &p1, &a1, &b1, &c1});
    detail::check_query(x, params, "vertex_face_ccd");
    CcdResult r;
    if (detail::boxes_apart(x, 1)) return r;
    // Coplanarity of (a, b, c, p): the filter's q0 is a; rows reordered.
    const detail::Points q = {x[1], x[2], x[3], x[0], x[5], x[6], x[7], x[4]};
    if (detail::never_coplanar(q)) {
        r.outcome = CcdOutcome::never_coplanar;
        return r;
    }
    detail::Motion m;
    detail::set_motion(x, m);
    detail::set_weights(x, m, 1, 2, 1, 3); // u along a → b, v along a → c
    return detail::inclusion_search(m, VertexFaceRange{m}, true, params);
}

} // namespace tethash::ccd
