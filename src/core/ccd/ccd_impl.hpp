#pragma once
// Private pieces of the continuous queries of include/tethash/ccd.hpp, shared by vertex_face.cpp and
// edge_edge.cpp: the input check, the two filters and the inclusion search over (t, u, v) boxes.
//
// A query is held as 8 points: rows 0-3 the four corners at t = 0, rows 4-7 the same corners at t = 1. The first
// `na` corners belong to primitive A (the vertex, or edge a), the others to B (the triangle, or edge b).
#include "tethash/ccd.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace tethash::ccd::detail {

/// Unit roundoff of double (2^-53).
inline constexpr double kEps = 1.1102230246251565e-16;
/// Largest coordinate magnitude accepted: products of three differences stay far from overflow.
inline constexpr double kMaxMagnitude = 1e50;
/// Absolute slack added to every error bound for underflow: below 2^-1074 per rounding, times at most
/// (2 · kMaxMagnitude)^2 through later products, far below this.
inline constexpr double kUnderflowSlack = 1e-200;

using Points = std::array<std::array<double, 3>, 8>;

inline Points gather(const Eigen::Vector3d* const (&in)[8])
{
    Points x;
    for (int i = 0; i < 8; ++i)
        for (int k = 0; k < 3; ++k)
            x[i][k] = (*in[i])(k);
    return x;
}

/// Throws Error when a coordinate is not finite or above kMaxMagnitude, or the parameters are bad.
void check_query(const Points& x, const CcdParams& params, const char* what);

/// Filter 1: true when the boxes of A's and of B's 8 corner positions (start and end) are apart on some axis.
/// Comparisons only, exact.
inline bool boxes_apart(const Points& x, int na)
{
    for (int k = 0; k < 3; ++k) {
        double alo = x[0][k], ahi = x[0][k], blo = x[na][k], bhi = x[na][k];
        for (int s = 0; s < 8; s += 4)
            for (int i = 0; i < 4; ++i) {
                const double c = x[s + i][k];
                if (i < na) {
                    alo = std::min(alo, c);
                    ahi = std::max(ahi, c);
                } else {
                    blo = std::min(blo, c);
                    bhi = std::max(bhi, c);
                }
            }
        if (ahi < blo || bhi < alo) return true;
    }
    return false;
}

/// det[c0, c1, c2] (columns) in Shewchuk's orient3d order of operations, and its permanent (the same sum of
/// products in absolute values), whose 8 ε multiple bounds the rounding of the determinant when each column entry
/// is one rounded difference of exact inputs (predicates.hpp's orient3d_error_bound).
inline double det3(const double* c0, const double* c1, const double* c2, double& permanent)
{
    const double m0 = c1[1] * c2[2] - c1[2] * c2[1];
    const double m1 = c2[1] * c0[2] - c2[2] * c0[1];
    const double m2 = c0[1] * c1[2] - c0[2] * c1[1];
    permanent = (std::abs(c1[1] * c2[2]) + std::abs(c1[2] * c2[1])) * std::abs(c0[0]) +
                (std::abs(c2[1] * c0[2]) + std::abs(c2[2] * c0[1])) * std::abs(c1[0]) +
                (std::abs(c0[1] * c1[2]) + std::abs(c0[2] * c1[1])) * std::abs(c2[0]);
    return c0[0] * m0 + c1[0] * m1 + c2[0] * m2;
}

/// Filter 2: true when the four points q0..q3 (rows i and 4 + i) are coplanar at no t in [0, 1].
/// g(t) = det[q1 - q0, q2 - q0, q3 - q0](t), each column moving linearly between its start and end values, is a
/// cubic; expanding the determinant by columns gives its Bernstein coefficient k as S_k / C(3, k), S_k the sum of
/// the determinants taking k columns at the end and 3 - k at the start. All S_k of one strict sign: no root. Each
/// determinant's rounding is below 8 ε its permanent; the two additions of a sum add 2 ε (1 + 3 ε) the sum of the
/// permanents: 12 ε of that sum bounds it, plus the underflow slack.
inline bool never_coplanar(const Points& x)
{
    double col[3][2][3]; // column i, at start (0) or end (1), axis
    for (int s = 0; s < 2; ++s)
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k)
                col[i][s][k] = x[4 * s + i + 1][k] - x[4 * s][k];
    double sum[4] = {0, 0, 0, 0}, perm[4] = {0, 0, 0, 0};
    for (int mask = 0; mask < 8; ++mask) {
        const int k = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1);
        double p = 0;
        sum[k] += det3(col[0][mask & 1], col[1][(mask >> 1) & 1], col[2][(mask >> 2) & 1], p);
        perm[k] += p;
    }
    bool positive = true, negative = true;
    for (int k = 0; k < 4; ++k) {
        const double err = 12.0 * kEps * perm[k] + kUnderflowSlack;
        positive = positive && sum[k] > err;
        negative = negative && sum[k] < -err;
    }
    return positive || negative;
}

/// A box of the parameters: t in [t0, t1], u in [u0, u1], v in [v0, v1].
struct Box {
    double t0, t1, u0, u1, v0, v1;
};

/// The query's data the search needs: start positions, displacements, error bounds and the splitting weights.
struct Motion {
    double x0[4][3];  ///< corners at t = 0
    double dx[4][3];  ///< rounded x1 - x0
    double err[3];    ///< bound on the rounding of a corner value of F, per axis
    double weight[3]; ///< how much F varies per unit of t, u, v (bound on the partial derivatives), for splitting
};

/// Start positions, displacements and the per-axis error bound: F's corner value is computed with at most 7
/// roundings, each of a value of magnitude at most 4 M (M the axis' largest coordinate magnitude); the sum of the
/// propagated errors is below 46 ε M for both queries (derivation in vertex_face.cpp and edge_edge.cpp): 64 ε M.
inline void set_motion(const Points& x, Motion& m)
{
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) {
            m.x0[i][k] = x[i][k];
            m.dx[i][k] = x[4 + i][k] - x[i][k];
        }
    for (int k = 0; k < 3; ++k) {
        double big = 0;
        for (int i = 0; i < 8; ++i)
            big = std::max(big, std::abs(x[i][k]));
        m.err[k] = 64.0 * kEps * big + kUnderflowSlack;
    }
}

/// The splitting weights of m (after set_motion): for t, the sum of the four points' displacements (the most F can
/// change from t = 0 to 1), per axis; for u and v, the largest extent along each axis, at either end of the step, of
/// the segments that u and v run along (rows u_from → u_to and v_from → v_to of the query's four points).
inline void set_weights(const Points& x, Motion& m, int u_from, int u_to, int v_from, int v_to)
{
    double wt = 0, wu = 0, wv = 0;
    for (int k = 0; k < 3; ++k) {
        double sum = 0;
        for (int i = 0; i < 4; ++i)
            sum += std::abs(m.dx[i][k]);
        wt = std::max(wt, sum);
        for (int s = 0; s < 8; s += 4) {
            wu = std::max(wu, std::abs(x[s + u_to][k] - x[s + u_from][k]));
            wv = std::max(wv, std::abs(x[s + v_to][k] - x[s + v_from][k]));
        }
    }
    m.weight[0] = wt;
    m.weight[1] = wu;
    m.weight[2] = wv;
}

/// True when n · F has one strict sign over the box. n · F is multilinear too, so its range is inside its corner
/// values'; each is computed with the corner values' errors (e_k per axis: Σ |n_k| e_k) plus the dot product's
/// rounding (3 roundings: 3.01 ε Σ |n_k| |F_k|). Any direction serves; `big[k]` bounds |F_k| at the corners.
inline bool one_sign_along(const double (&f)[8][3], const double* n, const double* err, const double* big)
{
    double e = kUnderflowSlack, scale = 0;
    for (int k = 0; k < 3; ++k) {
        e += std::abs(n[k]) * err[k];
        scale += std::abs(n[k]) * big[k];
    }
    e += 3.01 * kEps * scale;
    bool positive = true, negative = true;
    for (const auto& c : f) {
        const double g = n[0] * c[0] + n[1] * c[1] + n[2] * c[2];
        positive = positive && g > e;
        negative = negative && g < -e;
    }
    return positive || negative;
}

/// Exclusions of a box beyond the axes, along slanted directions. The axis-aligned ranges of F straddle 0 long after
/// its values lie on one side of a slanted plane (primitives approaching at an angle); so F is also tested along the
/// centre of its range (what the box's values have in common), and along the rows of the adjugate of F's Jacobian
/// over the box (estimated from the corner differences): those turn F into, nearly, the offset of the box from the
/// root in (t, u, v), so a box is dropped as soon as the root is outside it (the test of a preconditioned inclusion).
inline bool excluded_along_slants(const double (&f)[8][3], const double* lo, const double* hi, const double* err)
{
    double centre[3], big[3];
    for (int k = 0; k < 3; ++k) {
        centre[k] = 0.5 * (lo[k] + hi[k]);
        big[k] = std::max(std::abs(lo[k]), std::abs(hi[k]));
    }
    if (one_sign_along(f, centre, err, big)) return true;
    // Columns of the Jacobian (times the box's widths): mean differences across the box in t, u and v.
    double j[3][3] = {}; // j[axis][parameter]
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 4; ++c) {
            const int cu = (c & 1) | ((c & 2) << 1);
            j[k][0] += f[c + 4][k] - f[c][k];
            j[k][1] += f[cu + 2][k] - f[cu][k];
            j[k][2] += f[2 * c + 1][k] - f[2 * c][k];
        }
    // Rows of the adjugate: row p is the cross product of the Jacobian's other two columns (in cyclic order).
    double rows[3][3], widest = -1;
    int normal = 0;
    for (int p = 0; p < 3; ++p) {
        const int q = (p + 1) % 3, r = (p + 2) % 3;
        double* n = rows[p];
        n[0] = j[1][q] * j[2][r] - j[2][q] * j[1][r];
        n[1] = j[2][q] * j[0][r] - j[0][q] * j[2][r];
        n[2] = j[0][q] * j[1][r] - j[1][q] * j[0][r];
        if (one_sign_along(f, n, err, big)) return true;
        const double size = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        if (size > widest) {
            widest = size;
            normal = p;
        }
    }
    // When F's values span only a plane, or nearly (coplanar motion: the Jacobian's determinant vanishes, and the
    // adjugate's rows are all normal to the plane and see nothing), the in-plane directions normal to each column:
    // N × column p, N the largest adjugate row.
    const double* nn = rows[normal];
    double det = 0, column = 0;
    for (int k = 0; k < 3; ++k) {
        det += j[k][0] * rows[0][k];
        column = std::max({column, std::abs(j[k][0]), std::abs(j[k][1]), std::abs(j[k][2])});
    }
    if (!(std::abs(det) <= 1e-3 * std::sqrt(widest) * column)) return false;
    for (int p = 0; p < 3; ++p) {
        const double n[3] = {nn[1] * j[2][p] - nn[2] * j[1][p], nn[2] * j[0][p] - nn[0] * j[2][p],
                             nn[0] * j[1][p] - nn[1] * j[0][p]};
        if (one_sign_along(f, n, err, big)) return true;
    }
    return false;
}

/// The inclusion search. `range(box, f)` gives F's computed values at the 8 corners of the box; `triangle` drops
/// boxes wholly outside u + v <= 1. `best` is the earliest t0 of a box accepted so far; only roots before it matter,
/// so every box is cut to t < best (t1 = best) before it is examined and dropped when t0 >= best.
///
/// Order: the open box with the least t0 is taken from a heap, then searched depth first (the earlier half of a
/// split in t first) for up to kDive boxes, the rest going back to the heap. The dive reaches a contact after about
/// one box per split, and once `best` is set, the cut boxes near a contact are excluded at once (the primitives are
/// apart before it): a line or a patch of contacts at one time (parallel edges meeting, a vertex sliding on a face)
/// is not swept box by box. Going back to the least t0 after each dive keeps the search from walking down a curve of
/// contacts (crossing edges in a plane) one accepted box at a time.
///
/// Invariant: every root earlier than `best` lies in an open box (heap or dive); so when none is left `best` is no
/// later than the first contact, and when the cap is reached so is the least t0 still open.
template <class Range>
CcdResult inclusion_search(const Motion& m, const Range& range, bool triangle, const CcdParams& params)
{
    constexpr int kDive = 128;
    thread_local std::vector<Box> heap, dive;
    heap.clear();
    dive.clear();
    const auto later = [](const Box& a, const Box& b) { return a.t0 > b.t0; };
    heap.push_back({0, 1, 0, 1, 0, 1});
    CcdResult r;
    double best = std::numeric_limits<double>::infinity();
    bool unresolved = false; // a box accepted because it could not be split further
    int budget = 0;
    while (!heap.empty() || !dive.empty()) {
        if (dive.empty() || budget == 0) {
            for (const Box& o : dive) {
                heap.push_back(o);
                std::push_heap(heap.begin(), heap.end(), later);
            }
            dive.clear();
            std::pop_heap(heap.begin(), heap.end(), later);
            dive.push_back(heap.back());
            heap.pop_back();
            budget = kDive;
        }
        Box b = dive.back();
        dive.pop_back();
        --budget;
        if (b.t0 >= best) continue;
        if (r.iterations >= params.max_iterations) {
            for (const Box& o : heap)
                best = std::min(best, o.t0);
            for (const Box& o : dive)
                best = std::min(best, o.t0);
            r.hit = true;
            r.toi = std::min(best, b.t0);
            r.outcome = CcdOutcome::iteration_cap;
            return r;
        }
        ++r.iterations;
        b.t1 = std::min(b.t1, best);
        if (triangle && b.u0 + b.v0 > 1.0) continue; // rounding is monotone: the exact sum exceeds 1 too
        double f[8][3];
        range(b, f);
        double lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
            lo[k] = f[0][k];
            hi[k] = f[0][k];
            for (int c = 1; c < 8; ++c) {
                lo[k] = std::min(lo[k], f[c][k]);
                hi[k] = std::max(hi[k], f[c][k]);
            }
        }
        bool out = false, small = true;
        for (int k = 0; k < 3; ++k) {
            out = out || lo[k] > m.err[k] || hi[k] < -m.err[k];
            small = small && hi[k] - lo[k] <= params.tolerance;
        }
        if (!out) out = excluded_along_slants(f, lo, hi, m.err);
        if (out) continue;
        // Split the parameter along which F's corner values change most (corner index 4 it + 2 iu + iv).
        double wt = 0, wu = 0, wv = 0;
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 4; ++c) {
                wt = std::max(wt, std::abs(f[c + 4][k] - f[c][k]));
                const int cu = (c & 1) | ((c & 2) << 1); // corners with iu = 0
                wu = std::max(wu, std::abs(f[cu + 2][k] - f[cu][k]));
                wv = std::max(wv, std::abs(f[2 * c + 1][k] - f[2 * c][k]));
            }
        int dim = 0;
        if (wu > wt && wu >= wv)
            dim = 1;
        else if (wv > wt && wv > wu)
            dim = 2;
        Box lower = b, upper = b;
        bool split = false;
        if (!small) {
            double* lower_end = dim == 0 ? &lower.t1 : dim == 1 ? &lower.u1 : &lower.v1;
            double* upper_start = dim == 0 ? &upper.t0 : dim == 1 ? &upper.u0 : &upper.v0;
            const double a = *upper_start, z = *lower_end; // the box's interval on that parameter
            const double mid = 0.5 * (a + z);
            split = mid > a && mid < z;
            *lower_end = mid;
            *upper_start = mid;
        }
        if (!split) { // within the tolerance, or too narrow to split: a contact as early as this box
            best = b.t0;
            unresolved = unresolved || !small;
            continue;
        }
        dive.push_back(upper);
        dive.push_back(lower); // examined first
    }
    if (best <= 1.0) {
        r.hit = true;
        r.toi = best;
        r.outcome = unresolved ? CcdOutcome::iteration_cap : CcdOutcome::within_tolerance;
    } else {
        r.outcome = CcdOutcome::excluded;
    }
    return r;
}

} // namespace tethash::ccd::detail
