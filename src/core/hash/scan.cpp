// Stage-2 bucket scan: 8 entries at a time with AVX2 (float box test, cell test, own-vertex test as masks,
// survivors extracted by bit scan), or one at a time. The AVX2 version is compiled with a target attribute
// and chosen at run time, so one build runs everywhere and uses AVX2 where present.
#include "scan.hpp"
#include "../simd.hpp"

#include "tethash/predicates.hpp"

#include <cmath>
#include <cstdlib>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define TETHASH_X86 1
#endif

namespace tethash::detail {
namespace {

std::int32_t scan_scalar(const VertexTable& t, std::int32_t begin, std::int32_t end, const ScanQuery& q, Index* out,
                         ScanCounters& c)
{
    std::int32_t n = 0;
    c.scanned += end - begin;
    const std::uint32_t ckey = column_key(q.cx, q.cy);
    const auto zspan = static_cast<std::uint32_t>(q.z1 - q.z0);
    for (std::int32_t i = begin; i < end; ++i) {
        const std::uint32_t k = t.key[i];
        if ((k & key_column_mask) != ckey || (((k >> 22) - static_cast<std::uint32_t>(q.z0)) & 0x3ffu) > zspan) {
            ++c.collisions;
            continue;
        }
        if (!(t.x[i] >= q.lo[0] && t.x[i] <= q.hi[0] && t.y[i] >= q.lo[1] && t.y[i] <= q.hi[1] && t.z[i] >= q.lo[2] &&
              t.z[i] <= q.hi[2])) {
            ++c.box_rejections;
            continue;
        }
        const Index v = t.id[i];
        if (v == q.own[0] || v == q.own[1] || v == q.own[2] || v == q.own[3]) {
            ++c.own;
            continue;
        }
        out[n++] = v;
    }
    return n;
}

#ifdef TETHASH_X86
__attribute__((target("avx2,popcnt"))) std::int32_t scan_ranges_avx2(const VertexTable& t, const ScanRange* ranges,
                                                                     std::int32_t count, const ScanQuery& q, Index* out,
                                                                     ScanCounters& c)
{
    const __m256 lx = _mm256_set1_ps(q.lo[0]), ly = _mm256_set1_ps(q.lo[1]), lz = _mm256_set1_ps(q.lo[2]);
    const __m256 hx = _mm256_set1_ps(q.hi[0]), hy = _mm256_set1_ps(q.hi[1]), hz = _mm256_set1_ps(q.hi[2]);
    const __m256i o0 = _mm256_set1_epi32(q.own[0]), o1 = _mm256_set1_epi32(q.own[1]);
    const __m256i o2 = _mm256_set1_epi32(q.own[2]), o3 = _mm256_set1_epi32(q.own[3]);
    const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const float* X = t.x.data();
    const float* Y = t.y.data();
    const float* Z = t.z.data();
    const std::int32_t* ID = t.id.data();
    const std::uint32_t* KEY = t.key.data();
    const __m256i colmask = _mm256_set1_epi32(static_cast<int>(key_column_mask));
    const __m256i zmask = _mm256_set1_epi32(0x3ff);
    std::int32_t n = 0;
    std::int64_t coll = 0, boxr = 0, own = 0;
    for (std::int32_t r = 0; r < count; ++r) {
        const std::int32_t begin = ranges[r].begin, end = ranges[r].end;
        const __m256i qk = _mm256_set1_epi32(static_cast<int>(column_key(ranges[r].cx, ranges[r].cy)));
        const __m256i z0 = _mm256_set1_epi32(q.z0), zs = _mm256_set1_epi32(q.z1 - q.z0 + 1);
        c.scanned += end - begin;
        for (std::int32_t i = begin; i < end; i += 8) {
            const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(end - i), iota);
            const __m256i k = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(KEY + i));
            const __m256i dz = _mm256_and_si256(_mm256_sub_epi32(_mm256_srli_epi32(k, 22), z0), zmask);
            const __m256i cell =
                _mm256_and_si256(_mm256_cmpeq_epi32(_mm256_and_si256(k, colmask), qk), _mm256_cmpgt_epi32(zs, dz));
            const int mv = _mm256_movemask_ps(_mm256_castsi256_ps(valid));
            const int mc = _mm256_movemask_ps(_mm256_castsi256_ps(cell)) & mv;
            coll += __builtin_popcount(mv & ~mc);
            if (!mc) continue;
            const __m256 x = _mm256_loadu_ps(X + i), y = _mm256_loadu_ps(Y + i), z = _mm256_loadu_ps(Z + i);
            const __m256 inx = _mm256_and_ps(_mm256_cmp_ps(x, lx, _CMP_GE_OQ), _mm256_cmp_ps(x, hx, _CMP_LE_OQ));
            const __m256 iny = _mm256_and_ps(_mm256_cmp_ps(y, ly, _CMP_GE_OQ), _mm256_cmp_ps(y, hy, _CMP_LE_OQ));
            const __m256 inz = _mm256_and_ps(_mm256_cmp_ps(z, lz, _CMP_GE_OQ), _mm256_cmp_ps(z, hz, _CMP_LE_OQ));
            const int mb = _mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(inx, iny), inz)) & mc;
            boxr += __builtin_popcount(mc & ~mb);
            if (!mb) continue;
            const __m256i ids = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ID + i));
            const __m256i isown =
                _mm256_or_si256(_mm256_or_si256(_mm256_cmpeq_epi32(ids, o0), _mm256_cmpeq_epi32(ids, o1)),
                                _mm256_or_si256(_mm256_cmpeq_epi32(ids, o2), _mm256_cmpeq_epi32(ids, o3)));
            const int mo = _mm256_movemask_ps(_mm256_castsi256_ps(isown)) & mb;
            own += __builtin_popcount(mo);
            int keep = mb & ~mo;
            while (keep) {
                const int k = __builtin_ctz(static_cast<unsigned>(keep));
                out[n++] = ID[i + k];
                keep &= keep - 1;
            }
        }
    }
    c.collisions += coll;
    c.box_rejections += boxr;
    c.own += own;
    return n;
}

// Left-packing indices for the lean kernel: for a lane mask m, the lanes of m in ascending order (3-bit lane
// numbers, one per byte, widened with vpmovzxbd). 2 KB.
struct PackTable {
    std::uint64_t idx[256];
    constexpr PackTable() : idx()
    {
        for (int m = 0; m < 256; ++m) {
            std::uint64_t v = 0;
            int k = 0;
            for (int lane = 0; lane < 8; ++lane)
                if (m & (1 << lane)) v |= static_cast<std::uint64_t>(lane) << (8 * k++);
            idx[m] = v;
        }
    }
};
constexpr PackTable pack_table;

// The lean kernel, branch-free per 8 entries: box, cell (column of the range, z-run of the query) and own-vertex
// tests as lane masks, one movemask, survivors left-packed by a permutation from pack_table and stored 8 at a time
// (`out` has 8 ids of slack). No statistics. Without `ZTest` the cell test is the column alone (column_scan_kernel).
template <bool ZTest>
__attribute__((target("avx2,popcnt"))) std::int32_t scan_ranges_avx2_lean(const VertexTable& t, const ScanRange* ranges,
                                                                          std::int32_t count, const ScanQuery& q,
                                                                          Index* out, ScanCounters&)
{
    const __m256 lx = _mm256_set1_ps(q.lo[0]), ly = _mm256_set1_ps(q.lo[1]), lz = _mm256_set1_ps(q.lo[2]);
    const __m256 hx = _mm256_set1_ps(q.hi[0]), hy = _mm256_set1_ps(q.hi[1]), hz = _mm256_set1_ps(q.hi[2]);
    const __m256i o0 = _mm256_set1_epi32(q.own[0]), o1 = _mm256_set1_epi32(q.own[1]);
    const __m256i o2 = _mm256_set1_epi32(q.own[2]), o3 = _mm256_set1_epi32(q.own[3]);
    const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i colmask = _mm256_set1_epi32(static_cast<int>(key_column_mask));
    const __m256i zmask = _mm256_set1_epi32(0x3ff);
    const __m256i z0 = _mm256_set1_epi32(q.z0), zs = _mm256_set1_epi32(q.z1 - q.z0 + 1);
    const float* X = t.x.data();
    const float* Y = t.y.data();
    const float* Z = t.z.data();
    const std::int32_t* ID = t.id.data();
    const std::uint32_t* KEY = t.key.data();
    std::int32_t n = 0;
    for (std::int32_t r = 0; r < count; ++r) {
        const std::int32_t begin = ranges[r].begin, end = ranges[r].end;
        const __m256i qk = _mm256_set1_epi32(static_cast<int>(column_key(ranges[r].cx, ranges[r].cy)));
        std::int32_t i = begin;
        do {
            // Lanes past `end` read the next entries or the padding (NaN coordinates): masked off.
            const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(end - i), iota);
            const __m256 x = _mm256_loadu_ps(X + i), y = _mm256_loadu_ps(Y + i), z = _mm256_loadu_ps(Z + i);
            const __m256 inx = _mm256_and_ps(_mm256_cmp_ps(x, lx, _CMP_GE_OQ), _mm256_cmp_ps(x, hx, _CMP_LE_OQ));
            const __m256 iny = _mm256_and_ps(_mm256_cmp_ps(y, ly, _CMP_GE_OQ), _mm256_cmp_ps(y, hy, _CMP_LE_OQ));
            const __m256 inz = _mm256_and_ps(_mm256_cmp_ps(z, lz, _CMP_GE_OQ), _mm256_cmp_ps(z, hz, _CMP_LE_OQ));
            const __m256i k = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(KEY + i));
            __m256i cell = _mm256_cmpeq_epi32(_mm256_and_si256(k, colmask), qk);
            if constexpr (ZTest) {
                const __m256i dz = _mm256_and_si256(_mm256_sub_epi32(_mm256_srli_epi32(k, 22), z0), zmask);
                cell = _mm256_and_si256(cell, _mm256_cmpgt_epi32(zs, dz));
            }
            const __m256i ids = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ID + i));
            const __m256i isown =
                _mm256_or_si256(_mm256_or_si256(_mm256_cmpeq_epi32(ids, o0), _mm256_cmpeq_epi32(ids, o1)),
                                _mm256_or_si256(_mm256_cmpeq_epi32(ids, o2), _mm256_cmpeq_epi32(ids, o3)));
            const __m256i keep = _mm256_andnot_si256(
                isown, _mm256_and_si256(_mm256_and_si256(valid, cell),
                                        _mm256_castps_si256(_mm256_and_ps(_mm256_and_ps(inx, iny), inz))));
            const unsigned m = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(keep)));
            const __m256i perm =
                _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pack_table.idx + m)));
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + n), _mm256_permutevar8x32_epi32(ids, perm));
            n += __builtin_popcount(m);
            i += 8;
        } while (i < end);
    }
    return n;
}
#endif

std::int32_t filter_scalar(const FacePlanes& f, const double* P, const Index* cand, std::int32_t count, double* val,
                           std::int8_t* code, std::int32_t* kept)
{
    constexpr double E = predicates::orient3d_error_bound;
    std::int32_t k = 0;
    for (std::int32_t j = 0; j < count; ++j) {
        const double* p = P + 3 * static_cast<std::size_t>(cand[j]);
        int undecided = 0;
        bool outside = false;
        double v[4];
        for (int i = 0; i < 4; ++i) {
            const double dx = p[0] - f.rx[i], dy = p[1] - f.ry[i], dz = p[2] - f.rz[i];
            v[i] = f.nx[i] * dx + f.ny[i] * dy + f.nz[i] * dz;
            const double bound = E * (std::fabs(dx) * f.mx[i] + std::fabs(dy) * f.my[i] + std::fabs(dz) * f.mz[i]);
            outside |= v[i] < -bound;
            if (v[i] <= bound) undecided |= 1 << i;
        }
        if (outside) continue;
        for (int i = 0; i < 4; ++i)
            val[4 * k + i] = v[i];
        code[k] = static_cast<std::int8_t>(undecided);
        kept[k++] = j;
    }
    return k;
}

#ifdef TETHASH_X86
__attribute__((target("avx2"))) std::int32_t filter_avx2(const FacePlanes& f, const double* P, const Index* cand,
                                                         std::int32_t count, double* val, std::int8_t* code,
                                                         std::int32_t* kept)
{
    const __m256d rx = _mm256_load_pd(f.rx), ry = _mm256_load_pd(f.ry), rz = _mm256_load_pd(f.rz);
    const __m256d nx = _mm256_load_pd(f.nx), ny = _mm256_load_pd(f.ny), nz = _mm256_load_pd(f.nz);
    const __m256d mx = _mm256_load_pd(f.mx), my = _mm256_load_pd(f.my), mz = _mm256_load_pd(f.mz);
    const __m256d E = _mm256_set1_pd(predicates::orient3d_error_bound);
    const __m256d sign = _mm256_set1_pd(-0.0);
    std::int32_t k = 0;
    for (std::int32_t j = 0; j < count; ++j) {
        const double* p = P + 3 * static_cast<std::size_t>(cand[j]);
        const __m256d dx = _mm256_sub_pd(_mm256_broadcast_sd(p), rx);
        const __m256d dy = _mm256_sub_pd(_mm256_broadcast_sd(p + 1), ry);
        const __m256d dz = _mm256_sub_pd(_mm256_broadcast_sd(p + 2), rz);
        const __m256d v =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(nx, dx), _mm256_mul_pd(ny, dy)), _mm256_mul_pd(nz, dz));
        const __m256d perm = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(_mm256_andnot_pd(sign, dx), mx), _mm256_mul_pd(_mm256_andnot_pd(sign, dy), my)),
            _mm256_mul_pd(_mm256_andnot_pd(sign, dz), mz));
        const __m256d bound = _mm256_mul_pd(E, perm);
        const int out = _mm256_movemask_pd(_mm256_cmp_pd(v, _mm256_xor_pd(bound, sign), _CMP_LT_OQ));
        // Most candidates are certainly outside: only the others are written (values, undecided faces, index).
        if (out) continue;
        _mm256_storeu_pd(val + 4 * k, v);
        code[k] = static_cast<std::int8_t>(_mm256_movemask_pd(_mm256_cmp_pd(v, bound, _CMP_LE_OQ)));
        kept[k++] = j;
    }
    return k;
}
#endif

// Face i: p replaces vertex i; value = n_i · (p − r_i) (the orient3d evaluation order, so Shewchuk's bound
// holds); m_i are the permanent weights of the bound. Lanes: (ref, u, w) = (D, C, B), (D, A, C), (D, B, A), (A, B, C):
//   orient(p,b,c,d) = (p−d)·((c−d)×(b−d)),  orient(a,p,c,d) = (p−d)·((a−d)×(c−d)),
//   orient(a,b,p,d) = (p−d)·((b−d)×(a−d)),  orient(a,b,c,p) = (p−a)·((b−a)×(c−a)).
void faces_scalar(const double* A, const double* B, const double* C, const double* D, FacePlanes& f)
{
    const double* ref[4] = {D, D, D, A};
    const double* u[4] = {C, A, B, B};
    const double* w[4] = {B, C, A, C};
    for (int i = 0; i < 4; ++i) {
        const double ux = u[i][0] - ref[i][0], uy = u[i][1] - ref[i][1], uz = u[i][2] - ref[i][2];
        const double wx = w[i][0] - ref[i][0], wy = w[i][1] - ref[i][1], wz = w[i][2] - ref[i][2];
        f.nx[i] = uy * wz - uz * wy;
        f.ny[i] = uz * wx - ux * wz;
        f.nz[i] = ux * wy - uy * wx;
        f.mx[i] = std::fabs(uy * wz) + std::fabs(uz * wy);
        f.my[i] = std::fabs(uz * wx) + std::fabs(ux * wz);
        f.mz[i] = std::fabs(ux * wy) + std::fabs(uy * wx);
        f.rx[i] = ref[i][0];
        f.ry[i] = ref[i][1];
        f.rz[i] = ref[i][2];
    }
}

#ifdef TETHASH_X86
// The same operations as faces_scalar, four faces in the four lanes (same results bit for bit).
__attribute__((target("avx2"))) void faces_avx2(const double* A, const double* B, const double* C, const double* D,
                                                FacePlanes& f)
{
    const __m256d sign = _mm256_set1_pd(-0.0);
    __m256d r[3], u[3], w[3];
    for (int k = 0; k < 3; ++k) {
        r[k] = _mm256_setr_pd(D[k], D[k], D[k], A[k]);
        u[k] = _mm256_sub_pd(_mm256_setr_pd(C[k], A[k], B[k], B[k]), r[k]);
        w[k] = _mm256_sub_pd(_mm256_setr_pd(B[k], C[k], A[k], C[k]), r[k]);
    }
    const __m256d yz = _mm256_mul_pd(u[1], w[2]), zy = _mm256_mul_pd(u[2], w[1]);
    const __m256d zx = _mm256_mul_pd(u[2], w[0]), xz = _mm256_mul_pd(u[0], w[2]);
    const __m256d xy = _mm256_mul_pd(u[0], w[1]), yx = _mm256_mul_pd(u[1], w[0]);
    _mm256_store_pd(f.nx, _mm256_sub_pd(yz, zy));
    _mm256_store_pd(f.ny, _mm256_sub_pd(zx, xz));
    _mm256_store_pd(f.nz, _mm256_sub_pd(xy, yx));
    _mm256_store_pd(f.mx, _mm256_add_pd(_mm256_andnot_pd(sign, yz), _mm256_andnot_pd(sign, zy)));
    _mm256_store_pd(f.my, _mm256_add_pd(_mm256_andnot_pd(sign, zx), _mm256_andnot_pd(sign, xz)));
    _mm256_store_pd(f.mz, _mm256_add_pd(_mm256_andnot_pd(sign, xy), _mm256_andnot_pd(sign, yx)));
    _mm256_store_pd(f.rx, r[0]);
    _mm256_store_pd(f.ry, r[1]);
    _mm256_store_pd(f.rz, r[2]);
}
#endif

using FilterFn = std::int32_t (*)(const FacePlanes&, const double*, const Index*, std::int32_t, double*, std::int8_t*,
                                  std::int32_t*);

std::int32_t scan_ranges_scalar(const VertexTable& t, const ScanRange* ranges, std::int32_t count, const ScanQuery& q,
                                Index* out, ScanCounters& c)
{
    std::int32_t n = 0;
    ScanQuery qq = q;
    for (std::int32_t r = 0; r < count; ++r) {
        qq.cx = ranges[r].cx;
        qq.cy = ranges[r].cy;
        n += scan_scalar(t, ranges[r].begin, ranges[r].end, qq, out + n, c);
    }
    return n;
}

// Cell boxes too big for the key test (see cell_key): every entry's cell recomputed from its double position,
// with the same expression as the vertex table. Scalar; only tets spanning hundreds of cells get here.
std::int32_t scan_ranges_exact(const VertexTable& t, const ScanRange* ranges, std::int32_t count, const ScanQuery& q,
                               Index* out, ScanCounters& c, const double* P, double inv_cell)
{
    std::int32_t n = 0;
    for (std::int32_t r = 0; r < count; ++r) {
        const ScanRange& R = ranges[r];
        c.scanned += R.end - R.begin;
        for (std::int32_t i = R.begin; i < R.end; ++i) {
            const Index v = t.id[i];
            const double* p = P + 3 * static_cast<std::size_t>(v);
            const std::int32_t cz = floor_to_int(p[2] * inv_cell);
            if (floor_to_int(p[0] * inv_cell) != R.cx || floor_to_int(p[1] * inv_cell) != R.cy || cz < q.z0 ||
                cz > q.z1) {
                ++c.collisions;
                continue;
            }
            if (!(t.x[i] >= q.lo[0] && t.x[i] <= q.hi[0] && t.y[i] >= q.lo[1] && t.y[i] <= q.hi[1] &&
                  t.z[i] >= q.lo[2] && t.z[i] <= q.hi[2])) {
                ++c.box_rejections;
                continue;
            }
            if (v == q.own[0] || v == q.own[1] || v == q.own[2] || v == q.own[3]) {
                ++c.own;
                continue;
            }
            out[n++] = v;
        }
    }
    return n;
}

using ScanFn = std::int32_t (*)(const VertexTable&, const ScanRange*, std::int32_t, const ScanQuery&, Index*,
                                ScanCounters&);

ScanFn choose()
{
#ifdef TETHASH_X86
    if (avx2_kernels()) return scan_ranges_avx2;
#endif
    return scan_ranges_scalar;
}

const ScanFn chosen = choose();
#ifdef TETHASH_X86
const ScanFn chosen_lean = chosen == scan_ranges_avx2 ? scan_ranges_avx2_lean<true> : chosen;
const ScanFn chosen_column = chosen == scan_ranges_avx2 ? scan_ranges_avx2_lean<false> : chosen;
#else
const ScanFn chosen_lean = chosen;
const ScanFn chosen_column = chosen;
#endif
const FilterFn chosen_filter = chosen == scan_ranges_scalar ? filter_scalar
#ifdef TETHASH_X86
                                                            : filter_avx2;
#else
                                                            : filter_scalar;
#endif

} // namespace

std::int32_t scan_ranges(const VertexTable& table, const ScanRange* ranges, std::int32_t count, const ScanQuery& q,
                         Index* out, ScanCounters& counters, bool full_counts, const double* exact_positions,
                         double inv_cell)
{
    if (exact_positions) return scan_ranges_exact(table, ranges, count, q, out, counters, exact_positions, inv_cell);
    return (full_counts ? chosen : chosen_lean)(table, ranges, count, q, out, counters);
}

ScanKernel column_scan_kernel()
{
    return chosen_column;
}

std::int32_t scan_bucket_range(const VertexTable& table, std::int32_t begin, std::int32_t end, const ScanQuery& q,
                               Index* out, ScanCounters& counters)
{
    const ScanRange r{begin, end, q.cx, q.cy};
    return chosen(table, &r, 1, q, out, counters);
}

std::int32_t filter_candidates(const FacePlanes& f, const double* P, const Index* cand, std::int32_t count, double* val,
                               std::int8_t* code, std::int32_t* kept)
{
    return chosen_filter(f, P, cand, count, val, code, kept);
}

int face_planes(const double* A, const double* B, const double* C, const double* D, FacePlanes& f, bool& exact)
{
#ifdef TETHASH_X86
    if (chosen_filter == filter_avx2)
        faces_avx2(A, B, C, D, f);
    else
        faces_scalar(A, B, C, D, f);
#else
    faces_scalar(A, B, C, D, f);
#endif
    // orient(A, B, C, D) = face 3 at D, with the candidate filter's bound.
    const double dx = D[0] - f.rx[3], dy = D[1] - f.ry[3], dz = D[2] - f.rz[3];
    const double det = f.nx[3] * dx + f.ny[3] * dy + f.nz[3] * dz;
    const double bound = predicates::orient3d_error_bound *
                         (std::fabs(dx) * f.mx[3] + std::fabs(dy) * f.my[3] + std::fabs(dz) * f.mz[3]);
    int s;
    exact = false;
    if (det > bound)
        s = 1;
    else if (det < -bound)
        s = -1;
    else {
        s = predicates::orient3d_exact(A, B, C, D).sign;
        exact = true;
    }
    if (s < 0)
        for (int i = 0; i < 4; ++i) {
            f.nx[i] = -f.nx[i];
            f.ny[i] = -f.ny[i];
            f.nz[i] = -f.nz[i];
        }
    return s;
}

const char* scan_kernel_name()
{
    return chosen == scan_ranges_scalar ? "scalar" : "avx2";
}

} // namespace tethash::detail
