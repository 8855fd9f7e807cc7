// The closed inside test of many (vertex, tet) pairs, four at a time in AVX2 lanes (one pair per lane), with the
// operations of predicates::orient3d in its order, or one at a time with predicates::inside_tet.
#include "inside_batch.hpp"

#include "../simd.hpp"
#include "tethash/predicates.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define TETHASH_X86 1
#endif

namespace tethash::detail {
namespace {

std::int64_t inside_scalar(const double* P, const Index* tets, const Index* vertex, const Index* tet,
                           std::int32_t begin, std::int32_t end, std::uint8_t* inside, double* bary)
{
    std::int64_t exact = 0;
    for (std::int32_t j = begin; j < end; ++j) {
        const Index* tv = tets + 4 * static_cast<std::size_t>(tet[j]);
        const predicates::InsideResult r =
            predicates::inside_tet(P + 3 * static_cast<std::size_t>(vertex[j]), P + 3 * static_cast<std::size_t>(tv[0]),
                                   P + 3 * static_cast<std::size_t>(tv[1]), P + 3 * static_cast<std::size_t>(tv[2]),
                                   P + 3 * static_cast<std::size_t>(tv[3]));
        exact += r.exact_evaluations;
        inside[j] = r.inside;
        if (r.inside)
            for (int i = 0; i < 4; ++i)
                bary[4 * static_cast<std::size_t>(j) + static_cast<std::size_t>(i)] = r.bary[i];
    }
    return exact;
}

#ifdef TETHASH_X86
/// Four points, one per lane, as x, y, z vectors.
struct Points4 {
    __m256d x, y, z;
};

// 3 doubles into lanes 0-2 (lane 3: a copy of lane 2), without reading past them.
__attribute__((target("avx2"))) inline __m256d load3(const double* p)
{
    return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_set1_pd(p[2]), 1);
}

__attribute__((target("avx2"))) inline Points4 gather4(const double* p0, const double* p1, const double* p2,
                                                       const double* p3)
{
    const __m256d a = load3(p0), b = load3(p1), c = load3(p2), d = load3(p3);
    const __m256d ab_lo = _mm256_unpacklo_pd(a, b), ab_hi = _mm256_unpackhi_pd(a, b); // (x0 x1 | z0 z1), (y0 y1 | ..)
    const __m256d cd_lo = _mm256_unpacklo_pd(c, d), cd_hi = _mm256_unpackhi_pd(c, d);
    return {_mm256_permute2f128_pd(ab_lo, cd_lo, 0x20), _mm256_permute2f128_pd(ab_hi, cd_hi, 0x20),
            _mm256_permute2f128_pd(ab_lo, cd_lo, 0x31)};
}

/// predicates::orient3d's filter in four lanes: its value and the bound it compares with, the same operations in
/// the same order (no contraction: the target has no FMA).
__attribute__((target("avx2"))) inline void orient4(const Points4& a, const Points4& b, const Points4& c,
                                                    const Points4& d, __m256d& det, __m256d& bound)
{
    const __m256d sign = _mm256_set1_pd(-0.0);
    const __m256d adx = _mm256_sub_pd(a.x, d.x), ady = _mm256_sub_pd(a.y, d.y), adz = _mm256_sub_pd(a.z, d.z);
    const __m256d bdx = _mm256_sub_pd(b.x, d.x), bdy = _mm256_sub_pd(b.y, d.y), bdz = _mm256_sub_pd(b.z, d.z);
    const __m256d cdx = _mm256_sub_pd(c.x, d.x), cdy = _mm256_sub_pd(c.y, d.y), cdz = _mm256_sub_pd(c.z, d.z);
    const __m256d yz = _mm256_mul_pd(cdy, bdz), zy = _mm256_mul_pd(cdz, bdy);
    const __m256d zx = _mm256_mul_pd(cdz, bdx), xz = _mm256_mul_pd(cdx, bdz);
    const __m256d xy = _mm256_mul_pd(cdx, bdy), yx = _mm256_mul_pd(cdy, bdx);
    const __m256d nx = _mm256_sub_pd(yz, zy), ny = _mm256_sub_pd(zx, xz), nz = _mm256_sub_pd(xy, yx);
    det = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(adx, nx), _mm256_mul_pd(ady, ny)), _mm256_mul_pd(adz, nz));
    const __m256d px = _mm256_mul_pd(_mm256_andnot_pd(sign, adx),
                                     _mm256_add_pd(_mm256_andnot_pd(sign, yz), _mm256_andnot_pd(sign, zy)));
    const __m256d py = _mm256_mul_pd(_mm256_andnot_pd(sign, ady),
                                     _mm256_add_pd(_mm256_andnot_pd(sign, zx), _mm256_andnot_pd(sign, xz)));
    const __m256d pz = _mm256_mul_pd(_mm256_andnot_pd(sign, adz),
                                     _mm256_add_pd(_mm256_andnot_pd(sign, xy), _mm256_andnot_pd(sign, yx)));
    bound = _mm256_mul_pd(_mm256_set1_pd(predicates::orient3d_error_bound), _mm256_add_pd(_mm256_add_pd(px, py), pz));
}

// The lanes where orient3d's filter decides: det > bound or −det > bound.
__attribute__((target("avx2"))) inline __m256d decided(__m256d det, __m256d bound)
{
    return _mm256_or_pd(_mm256_cmp_pd(det, bound, _CMP_GT_OQ),
                        _mm256_cmp_pd(_mm256_xor_pd(det, _mm256_set1_pd(-0.0)), bound, _CMP_GT_OQ));
}

// Four pairs per step. A lane is decided when all five filters decide their signs (then every sign is ±1, as
// orient3d returns it); its result is inside_tet's: inside iff no face has the sign opposite to the tet's, bary the
// values over their sum taken in order. A lane whose tet orientation is decided and one of whose faces is decided
// with the opposite sign is outside, as inside_tet finds it, without the exact evaluations inside_tet would make of
// the undecided faces before it; any other lane with an undecided filter goes to inside_tet.
__attribute__((target("avx2"))) std::int64_t inside_avx2(const double* P, const Index* tets, const Index* vertex,
                                                         const Index* tet, std::int32_t count, std::uint8_t* inside,
                                                         double* bary)
{
    std::int64_t exact = 0;
    std::int32_t j = 0;
    for (; j + 4 <= count; j += 4) {
        const double* p[4];
        const double* q[4][4];
        for (int l = 0; l < 4; ++l) {
            p[l] = P + 3 * static_cast<std::size_t>(vertex[j + l]);
            const Index* tv = tets + 4 * static_cast<std::size_t>(tet[j + l]);
            for (int k = 0; k < 4; ++k)
                q[k][l] = P + 3 * static_cast<std::size_t>(tv[k]);
        }
        const Points4 pp = gather4(p[0], p[1], p[2], p[3]);
        const Points4 a = gather4(q[0][0], q[0][1], q[0][2], q[0][3]);
        const Points4 b = gather4(q[1][0], q[1][1], q[1][2], q[1][3]);
        const Points4 c = gather4(q[2][0], q[2][1], q[2][2], q[2][3]);
        const Points4 d = gather4(q[3][0], q[3][1], q[3][2], q[3][3]);
        __m256d o, ob, f[4], fb[4];
        orient4(a, b, c, d, o, ob);
        orient4(pp, b, c, d, f[0], fb[0]);
        orient4(a, pp, c, d, f[1], fb[1]);
        orient4(a, b, pp, d, f[2], fb[2]);
        orient4(a, b, c, pp, f[3], fb[3]);
        // Decided: det > bound or −det > bound, for all five.
        const __m256d odecided = decided(o, ob);
        __m256d fd[4], all = odecided;
        for (int i = 0; i < 4; ++i) {
            fd[i] = decided(f[i], fb[i]);
            all = _mm256_and_pd(all, fd[i]);
        }
        const __m256d opos = _mm256_cmp_pd(o, _mm256_setzero_pd(), _CMP_GT_OQ);
        int decided_mask = _mm256_movemask_pd(all);
        if (decided_mask != 15) {
            // Rejected: the tet's sign decided and a face's decided opposite to it (f > 0 where o < 0, f < 0 where
            // o > 0: the decided f is not 0).
            __m256d rejected = _mm256_setzero_pd();
            for (int i = 0; i < 4; ++i)
                rejected = _mm256_or_pd(
                    rejected,
                    _mm256_and_pd(fd[i], _mm256_xor_pd(_mm256_cmp_pd(f[i], _mm256_setzero_pd(), _CMP_GT_OQ), opos)));
            decided_mask |= _mm256_movemask_pd(_mm256_and_pd(rejected, odecided));
        }
        // Inside (decided lanes): every face value has the sign of the tet's.
        __m256d same = all;
        for (int i = 0; i < 4; ++i)
            same = _mm256_and_pd(same, _mm256_xor_pd(_mm256_cmp_pd(f[i], _mm256_setzero_pd(), _CMP_LE_OQ), opos));
        const __m256d sum =
            _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_setzero_pd(), f[0]), f[1]), f[2]), f[3]);
        alignas(32) double w[4][4];
        for (int i = 0; i < 4; ++i)
            _mm256_store_pd(w[i], _mm256_div_pd(f[i], sum));
        const int in_mask = _mm256_movemask_pd(same);
        for (int l = 0; l < 4; ++l) {
            if (!(decided_mask >> l & 1)) {
                exact += inside_scalar(P, tets, vertex, tet, j + l, j + l + 1, inside, bary);
                continue;
            }
            const bool in = in_mask >> l & 1;
            inside[j + l] = in;
            if (in)
                for (int i = 0; i < 4; ++i)
                    bary[4 * static_cast<std::size_t>(j + l) + static_cast<std::size_t>(i)] = w[i][l];
        }
    }
    return exact + inside_scalar(P, tets, vertex, tet, j, count, inside, bary);
}
#endif

using InsideFn = std::int64_t (*)(const double*, const Index*, const Index*, const Index*, std::int32_t, std::uint8_t*,
                                  double*);

std::int64_t inside_all_scalar(const double* P, const Index* tets, const Index* vertex, const Index* tet,
                               std::int32_t count, std::uint8_t* inside, double* bary)
{
    return inside_scalar(P, tets, vertex, tet, 0, count, inside, bary);
}

InsideFn choose()
{
#ifdef TETHASH_X86
    if (avx2_kernels()) return inside_avx2;
#endif
    return inside_all_scalar;
}

const InsideFn chosen = choose();

} // namespace

std::int64_t inside_tets(const double* P, const Index* tets, const Index* vertex, const Index* tet, std::int32_t count,
                         std::uint8_t* inside, double* bary)
{
    return chosen(P, tets, vertex, tet, count, inside, bary);
}

} // namespace tethash::detail
