// The block-descent gather, four lanes at a time (AVX2 + FMA) or one lane at a time (vertex_stencils.hpp).
// Both compute, per lane: springs f −= k ((l − L0) + d/h (l − l_t)) u, H += k (1 − L0/l)⁺ I + k ((1 − tr) + d/h) uuᵀ
// (transverse part clamped at 0 when compressed; a zero-length spring is skipped) and volume terms
// f += k36 ((W − W0) + d/h (W − W_t)) N, H += k36 (1 + d/h) N Nᵀ.
#include "vertex_stencils.hpp"

#include "core/simd.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define TETHASH_X86 1
#endif

namespace tethash::sim::detail {
namespace {

/// Lane l of a volume entry at vertex position (px, py, pz): W = (a − p) · N with N = (b − a) × (c − a), the
/// opposite face's corners a, b, c read from x. Sets n to N.
inline double volume_term(const TetLanes& t, int l, const double* x, double px, double py, double pz, double n[3])
{
    const double* a = x + 4 * static_cast<std::size_t>(t.a[l]);
    const double* b = x + 4 * static_cast<std::size_t>(t.b[l]);
    const double* c = x + 4 * static_cast<std::size_t>(t.c[l]);
    const double bax = b[0] - a[0], bay = b[1] - a[1], baz = b[2] - a[2];
    const double cax = c[0] - a[0], cay = c[1] - a[1], caz = c[2] - a[2];
    n[0] = bay * caz - baz * cay;
    n[1] = baz * cax - bax * caz;
    n[2] = bax * cay - bay * cax;
    return (a[0] - px) * n[0] + (a[1] - py) * n[1] + (a[2] - pz) * n[2];
}

template <bool Guard>
void gather_scalar(const LaneGroup& g, const SpringLanes* springs, const TetLanes* tets, const double* x, double inv_h,
                   LaneTerms& out)
{
    // The lanes side by side (padding lanes too: they read lane 0's vertex and their output is not used), so
    // that the compiler can use whatever vector width the baseline target has.
    double xi[4], yi[4], zi[4], dh[4];
    for (int l = 0; l < 4; ++l) {
        const double* p = x + 4 * static_cast<std::size_t>(g.vertex[l]);
        xi[l] = p[0];
        yi[l] = p[1];
        zi[l] = p[2];
        dh[l] = g.damping[l] * inv_h;
    }
    double f[3][4] = {}, H[6][4] = {};
    double reach2[4];
    std::fill(std::begin(reach2), std::end(reach2), std::numeric_limits<double>::infinity());
    for (std::int32_t s = g.spring_begin; s < g.spring_end; ++s) {
        const SpringLanes& sp = springs[s];
        for (int l = 0; l < 4; ++l) {
            const double* xj = x + 4 * static_cast<std::size_t>(sp.other[l]);
            const double dx = xi[l] - xj[0], dy = yi[l] - xj[1], dz = zi[l] - xj[2];
            const double len2 = dx * dx + dy * dy + dz * dz;
            if (!(len2 > 0)) continue;
            const double len = std::sqrt(len2), inv = 1.0 / len;
            const double ux = dx * inv, uy = dy * inv, uz = dz * inv;
            const double k = sp.k[l];
            const double stretch = len - sp.rest[l];
            const double fs = k * (stretch + dh[l] * (stretch - static_cast<double>(sp.stretch_t[l])));
            f[0][l] -= fs * ux;
            f[1][l] -= fs * uy;
            f[2][l] -= fs * uz;
            const double tr = std::max(0.0, 1.0 - sp.rest[l] * inv);
            const double kt = k * tr, ko = k * (1.0 - tr) + dh[l] * k;
            H[0][l] += kt + ko * ux * ux;
            H[1][l] += kt + ko * uy * uy;
            H[2][l] += kt + ko * uz * uz;
            H[3][l] += ko * ux * uy;
            H[4][l] += ko * ux * uz;
            H[5][l] += ko * uy * uz;
        }
    }
    for (std::int32_t s = g.tet_begin; s < g.tet_end; ++s) {
        const TetLanes& t = tets[s];
        for (int l = 0; l < 4; ++l) {
            double n[3];
            const double w = volume_term(t, l, x, xi[l], yi[l], zi[l], n);
            const double nx = n[0], ny = n[1], nz = n[2];
            const double excess = w - t.w0[l];
            const double fs = t.k36[l] * (excess + dh[l] * (excess - static_cast<double>(t.excess_t[l])));
            f[0][l] += fs * nx;
            f[1][l] += fs * ny;
            f[2][l] += fs * nz;
            const double ks = t.k36[l] * (1.0 + dh[l]);
            H[0][l] += ks * nx * nx;
            H[1][l] += ks * ny * ny;
            H[2][l] += ks * nz * nz;
            H[3][l] += ks * nx * ny;
            H[4][l] += ks * nx * nz;
            H[5][l] += ks * ny * nz;
            if (Guard && t.guard[l] > 0 && w > 0) {
                const double slack = std::max(0.0, w - static_cast<double>(t.guard[l]));
                reach2[l] = std::min(reach2[l], slack * slack / (nx * nx + ny * ny + nz * nz));
            }
        }
    }
    std::memcpy(out.f, f, sizeof(f));
    std::memcpy(out.H, H, sizeof(H));
    std::memcpy(out.reach2, reach2, sizeof(reach2));
}

} // namespace

double guarded_fraction(const LaneGroup& g, const TetLanes* tets, int l, const double* x, const double d[3])
{
    const double* p = x + 4 * static_cast<std::size_t>(g.vertex[l]);
    double t_max = std::numeric_limits<double>::infinity();
    for (std::int32_t s = g.tet_begin; s < g.tet_end; ++s) {
        const TetLanes& t = tets[s];
        if (!(t.guard[l] > 0)) continue;
        double n[3];
        const double w = volume_term(t, l, x, p[0], p[1], p[2], n);
        const double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2]; // W(p + d) = W − N·d
        if (!(w > 0) || !(nd > 0)) continue;
        t_max = std::min(t_max, std::max(0.0, w - static_cast<double>(t.guard[l])) / nd);
    }
    return std::min(1.0, 0.9 * t_max);
}

namespace {

void start_scalar(const LaneGroup& g, SpringLanes* springs, TetLanes* tets, const double* x)
{
    for (std::int32_t s = g.spring_begin; s < g.spring_end; ++s) {
        SpringLanes& sp = springs[s];
        for (int l = 0; l < 4; ++l) {
            const double* xi = x + 4 * static_cast<std::size_t>(g.vertex[l]);
            const double* xj = x + 4 * static_cast<std::size_t>(sp.other[l]);
            const double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
            sp.stretch_t[l] = static_cast<float>(std::sqrt(dx * dx + dy * dy + dz * dz) - sp.rest[l]);
        }
    }
    for (std::int32_t s = g.tet_begin; s < g.tet_end; ++s) {
        TetLanes& t = tets[s];
        for (int l = 0; l < 4; ++l) {
            const double* xi = x + 4 * static_cast<std::size_t>(g.vertex[l]);
            double n[3];
            t.excess_t[l] = static_cast<float>(volume_term(t, l, x, xi[0], xi[1], xi[2], n) - t.w0[l]);
        }
    }
}

int solve_scalar(const LaneTerms& t, double d[3][4])
{
    int solved = 0;
    for (int l = 0; l < 4; ++l) {
        const double xx = t.H[0][l], yy = t.H[1][l], zz = t.H[2][l], xy = t.H[3][l], xz = t.H[4][l], yz = t.H[5][l];
        if (!(xx > 0)) continue;
        const double r11 = std::sqrt(xx);
        const double l21 = xy / r11, l31 = xz / r11;
        const double l22sq = yy - l21 * l21;
        if (!(l22sq > 0)) continue;
        const double r22 = std::sqrt(l22sq);
        const double l32 = (yz - l31 * l21) / r22;
        const double l33sq = zz - l31 * l31 - l32 * l32;
        if (!(l33sq > 0)) continue;
        const double r33 = std::sqrt(l33sq);
        const double z1 = t.f[0][l] / r11;
        const double z2 = (t.f[1][l] - l21 * z1) / r22;
        const double z3 = (t.f[2][l] - l31 * z1 - l32 * z2) / r33;
        d[2][l] = z3 / r33;
        d[1][l] = (z2 - l32 * d[2][l]) / r22;
        d[0][l] = (z1 - l21 * d[1][l] - l31 * d[2][l]) / r11;
        solved |= 1 << l;
    }
    return solved;
}

#ifdef TETHASH_X86
/// Loads the coordinates of the four vertices `ids` (positions with a stride of 4 doubles, 32-byte aligned):
/// four row loads and a 4 × 4 transpose. (Three vgatherdpd instead were slower: docs/simulator.md.)
__attribute__((target("avx2,fma"), always_inline)) inline void load3(const double* x, const std::int32_t* ids,
                                                                     __m256d& px, __m256d& py, __m256d& pz)
{
    const __m256d r0 = _mm256_load_pd(x + 4 * static_cast<std::size_t>(ids[0]));
    const __m256d r1 = _mm256_load_pd(x + 4 * static_cast<std::size_t>(ids[1]));
    const __m256d r2 = _mm256_load_pd(x + 4 * static_cast<std::size_t>(ids[2]));
    const __m256d r3 = _mm256_load_pd(x + 4 * static_cast<std::size_t>(ids[3]));
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1); // x0 x1 z0 z1
    const __m256d t1 = _mm256_unpackhi_pd(r0, r1); // y0 y1 . .
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3); // x2 x3 z2 z3
    const __m256d t3 = _mm256_unpackhi_pd(r2, r3); // y2 y3 . .
    px = _mm256_permute2f128_pd(t0, t2, 0x20);
    py = _mm256_permute2f128_pd(t1, t3, 0x20);
    pz = _mm256_permute2f128_pd(t0, t2, 0x31);
}

/// For four tets (one per lane) with corners a, b, c opposite the lane's vertex (xi, yi, zi): the face normal
/// n = (b − a) × (c − a) and w = (a − x)·n, six times the signed volume, which the return value holds.
__attribute__((target("avx2,fma"), always_inline)) inline __m256d face_normal_and_w(const double* x, const TetLanes& t,
                                                                                    __m256d xi, __m256d yi, __m256d zi,
                                                                                    __m256d& nx, __m256d& ny,
                                                                                    __m256d& nz)
{
    __m256d ax, ay, az, bx, by, bz, cx, cy, cz;
    load3(x, t.a, ax, ay, az);
    load3(x, t.b, bx, by, bz);
    load3(x, t.c, cx, cy, cz);
    const __m256d bax = _mm256_sub_pd(bx, ax), bay = _mm256_sub_pd(by, ay), baz = _mm256_sub_pd(bz, az);
    const __m256d cax = _mm256_sub_pd(cx, ax), cay = _mm256_sub_pd(cy, ay), caz = _mm256_sub_pd(cz, az);
    nx = _mm256_fmsub_pd(bay, caz, _mm256_mul_pd(baz, cay));
    ny = _mm256_fmsub_pd(baz, cax, _mm256_mul_pd(bax, caz));
    nz = _mm256_fmsub_pd(bax, cay, _mm256_mul_pd(bay, cax));
    return _mm256_fmadd_pd(_mm256_sub_pd(ax, xi), nx,
                           _mm256_fmadd_pd(_mm256_sub_pd(ay, yi), ny, _mm256_mul_pd(_mm256_sub_pd(az, zi), nz)));
}

template <bool Guard>
__attribute__((target("avx2,fma"))) void gather_avx2(const LaneGroup& g, const SpringLanes* springs,
                                                     const TetLanes* tets, const double* x, double inv_h,
                                                     LaneTerms& out)
{
    __m256d xi, yi, zi;
    load3(x, g.vertex, xi, yi, zi);
    const __m256d dh = _mm256_mul_pd(_mm256_load_pd(g.damping), _mm256_set1_pd(inv_h));
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    __m256d fx = zero, fy = zero, fz = zero;
    __m256d hxx = zero, hyy = zero, hzz = zero, hxy = zero, hxz = zero, hyz = zero;
    for (std::int32_t s = g.spring_begin; s < g.spring_end; ++s) {
        const SpringLanes& sp = springs[s];
        __m256d ox, oy, oz;
        load3(x, sp.other, ox, oy, oz);
        const __m256d dx = _mm256_sub_pd(xi, ox), dy = _mm256_sub_pd(yi, oy), dz = _mm256_sub_pd(zi, oz);
        const __m256d len2 = _mm256_fmadd_pd(dx, dx, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dz, dz)));
        const __m256d live = _mm256_cmp_pd(len2, zero, _CMP_GT_OQ); // a zero-length spring (or padding) is skipped
        const __m256d len = _mm256_sqrt_pd(len2);
        const __m256d inv = _mm256_and_pd(live, _mm256_div_pd(one, len));
        const __m256d k = _mm256_and_pd(live, _mm256_cvtps_pd(_mm_load_ps(sp.k)));
        const __m256d rest = _mm256_load_pd(sp.rest);
        const __m256d ux = _mm256_mul_pd(dx, inv), uy = _mm256_mul_pd(dy, inv), uz = _mm256_mul_pd(dz, inv);
        const __m256d s0 = _mm256_sub_pd(len, rest);
        const __m256d stretch = _mm256_fmadd_pd(dh, _mm256_sub_pd(s0, _mm256_cvtps_pd(_mm_load_ps(sp.stretch_t))), s0);
        const __m256d fs = _mm256_and_pd(live, _mm256_mul_pd(k, stretch));
        fx = _mm256_fnmadd_pd(fs, ux, fx);
        fy = _mm256_fnmadd_pd(fs, uy, fy);
        fz = _mm256_fnmadd_pd(fs, uz, fz);
        const __m256d tr = _mm256_max_pd(zero, _mm256_fnmadd_pd(rest, inv, one));
        const __m256d kt = _mm256_mul_pd(k, tr);
        const __m256d ko = _mm256_mul_pd(k, _mm256_add_pd(_mm256_sub_pd(one, tr), dh));
        const __m256d kux = _mm256_mul_pd(ko, ux), kuy = _mm256_mul_pd(ko, uy);
        hxx = _mm256_add_pd(hxx, _mm256_fmadd_pd(kux, ux, kt));
        hyy = _mm256_add_pd(hyy, _mm256_fmadd_pd(kuy, uy, kt));
        hzz = _mm256_add_pd(hzz, _mm256_fmadd_pd(_mm256_mul_pd(ko, uz), uz, kt));
        hxy = _mm256_fmadd_pd(kux, uy, hxy);
        hxz = _mm256_fmadd_pd(kux, uz, hxz);
        hyz = _mm256_fmadd_pd(kuy, uz, hyz);
    }
    const __m256d tet_scale = _mm256_add_pd(one, dh);
    const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
    __m256d reach2 = inf;
    for (std::int32_t s = g.tet_begin; s < g.tet_end; ++s) {
        const TetLanes& t = tets[s];
        __m256d nx, ny, nz;
        const __m256d w = face_normal_and_w(x, t, xi, yi, zi, nx, ny, nz);
        const __m256d k36 = _mm256_cvtps_pd(_mm_load_ps(t.k36));
        const __m256d e0 = _mm256_sub_pd(w, _mm256_load_pd(t.w0));
        const __m256d excess = _mm256_fmadd_pd(dh, _mm256_sub_pd(e0, _mm256_cvtps_pd(_mm_load_ps(t.excess_t))), e0);
        const __m256d fs = _mm256_mul_pd(k36, excess);
        fx = _mm256_fmadd_pd(fs, nx, fx);
        fy = _mm256_fmadd_pd(fs, ny, fy);
        fz = _mm256_fmadd_pd(fs, nz, fz);
        const __m256d ks = _mm256_mul_pd(k36, tet_scale);
        const __m256d knx = _mm256_mul_pd(ks, nx), kny = _mm256_mul_pd(ks, ny);
        hxx = _mm256_fmadd_pd(knx, nx, hxx);
        hyy = _mm256_fmadd_pd(kny, ny, hyy);
        hzz = _mm256_fmadd_pd(_mm256_mul_pd(ks, nz), nz, hzz);
        hxy = _mm256_fmadd_pd(knx, ny, hxy);
        hxz = _mm256_fmadd_pd(knx, nz, hxz);
        hyz = _mm256_fmadd_pd(kny, nz, hyz);
        if constexpr (Guard) {
            const __m256d tau = _mm256_cvtps_pd(_mm_load_ps(t.guard));
            const __m256d guarded =
                _mm256_and_pd(_mm256_cmp_pd(tau, zero, _CMP_GT_OQ), _mm256_cmp_pd(w, zero, _CMP_GT_OQ));
            const __m256d slack = _mm256_max_pd(zero, _mm256_sub_pd(w, tau));
            const __m256d n2 = _mm256_fmadd_pd(nx, nx, _mm256_fmadd_pd(ny, ny, _mm256_mul_pd(nz, nz)));
            const __m256d r2 = _mm256_div_pd(_mm256_mul_pd(slack, slack), n2);
            reach2 = _mm256_min_pd(reach2, _mm256_blendv_pd(inf, r2, guarded));
        }
    }
    _mm256_store_pd(out.reach2, reach2);
    _mm256_store_pd(out.f[0], fx);
    _mm256_store_pd(out.f[1], fy);
    _mm256_store_pd(out.f[2], fz);
    _mm256_store_pd(out.H[0], hxx);
    _mm256_store_pd(out.H[1], hyy);
    _mm256_store_pd(out.H[2], hzz);
    _mm256_store_pd(out.H[3], hxy);
    _mm256_store_pd(out.H[4], hxz);
    _mm256_store_pd(out.H[5], hyz);
}

__attribute__((target("avx2,fma"))) void start_avx2(const LaneGroup& g, SpringLanes* springs, TetLanes* tets,
                                                    const double* x)
{
    __m256d xi, yi, zi;
    load3(x, g.vertex, xi, yi, zi);
    for (std::int32_t s = g.spring_begin; s < g.spring_end; ++s) {
        SpringLanes& sp = springs[s];
        __m256d ox, oy, oz;
        load3(x, sp.other, ox, oy, oz);
        const __m256d dx = _mm256_sub_pd(xi, ox), dy = _mm256_sub_pd(yi, oy), dz = _mm256_sub_pd(zi, oz);
        const __m256d len = _mm256_sqrt_pd(_mm256_fmadd_pd(dx, dx, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dz, dz))));
        _mm_store_ps(sp.stretch_t, _mm256_cvtpd_ps(_mm256_sub_pd(len, _mm256_load_pd(sp.rest))));
    }
    for (std::int32_t s = g.tet_begin; s < g.tet_end; ++s) {
        TetLanes& t = tets[s];
        __m256d nx, ny, nz;
        const __m256d w = face_normal_and_w(x, t, xi, yi, zi, nx, ny, nz);
        _mm_store_ps(t.excess_t, _mm256_cvtpd_ps(_mm256_sub_pd(w, _mm256_load_pd(t.w0))));
    }
}

__attribute__((target("avx2,fma"))) int solve_avx2(const LaneTerms& t, double d[3][4])
{
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    const __m256d xx = _mm256_load_pd(t.H[0]), yy = _mm256_load_pd(t.H[1]), zz = _mm256_load_pd(t.H[2]);
    const __m256d xy = _mm256_load_pd(t.H[3]), xz = _mm256_load_pd(t.H[4]), yz = _mm256_load_pd(t.H[5]);
    // H = L Lᵀ with L's diagonal kept as reciprocals (i11 = 1 / L11 …); a lane is solved when every pivot is > 0.
    __m256d ok = _mm256_cmp_pd(xx, zero, _CMP_GT_OQ);
    const __m256d i11 = _mm256_div_pd(one, _mm256_sqrt_pd(xx));
    const __m256d l21 = _mm256_mul_pd(xy, i11), l31 = _mm256_mul_pd(xz, i11);
    const __m256d p22 = _mm256_fnmadd_pd(l21, l21, yy);
    ok = _mm256_and_pd(ok, _mm256_cmp_pd(p22, zero, _CMP_GT_OQ));
    const __m256d i22 = _mm256_div_pd(one, _mm256_sqrt_pd(p22));
    const __m256d l32 = _mm256_mul_pd(_mm256_fnmadd_pd(l31, l21, yz), i22);
    const __m256d p33 = _mm256_fnmadd_pd(l32, l32, _mm256_fnmadd_pd(l31, l31, zz));
    ok = _mm256_and_pd(ok, _mm256_cmp_pd(p33, zero, _CMP_GT_OQ));
    const __m256d i33 = _mm256_div_pd(one, _mm256_sqrt_pd(p33));
    const __m256d z1 = _mm256_mul_pd(_mm256_load_pd(t.f[0]), i11);
    const __m256d z2 = _mm256_mul_pd(_mm256_fnmadd_pd(l21, z1, _mm256_load_pd(t.f[1])), i22);
    const __m256d z3 = _mm256_mul_pd(_mm256_fnmadd_pd(l32, z2, _mm256_fnmadd_pd(l31, z1, _mm256_load_pd(t.f[2]))), i33);
    const __m256d d2 = _mm256_mul_pd(z3, i33);
    const __m256d d1 = _mm256_mul_pd(_mm256_fnmadd_pd(l32, d2, z2), i22);
    const __m256d d0 = _mm256_mul_pd(_mm256_fnmadd_pd(l31, d2, _mm256_fnmadd_pd(l21, d1, z1)), i11);
    _mm256_storeu_pd(d[0], d0);
    _mm256_storeu_pd(d[1], d1);
    _mm256_storeu_pd(d[2], d2);
    return _mm256_movemask_pd(ok);
}
#endif

/// The kernels that go together, the scalar ones last (what an unknown gather is matched with).
struct KernelSet {
    GatherFn gather, guarded_gather;
    StartFn start;
    SolveFn solve;
    const char* name;
};

constexpr KernelSet k_kernel_sets[] = {
#ifdef TETHASH_X86
    {gather_avx2<false>, gather_avx2<true>, start_avx2, solve_avx2, "avx2"},
#endif
    {gather_scalar<false>, gather_scalar<true>, start_scalar, solve_scalar, "scalar"},
};

const KernelSet& kernels_of(GatherFn gather)
{
    for (const KernelSet& k : k_kernel_sets)
        if (k.gather == gather || k.guarded_gather == gather) return k;
    return k_kernel_sets[std::size(k_kernel_sets) - 1];
}

} // namespace

SolveFn choose_solve(GatherFn gather)
{
    return kernels_of(gather).solve;
}

StartFn choose_start(GatherFn gather)
{
    return kernels_of(gather).start;
}

GatherFn choose_gather(bool inversion_guard)
{
    const KernelSet* set = &k_kernel_sets[std::size(k_kernel_sets) - 1]; // the scalar kernels
#ifdef TETHASH_X86
    if (tethash::detail::avx2_kernels(true)) set = &k_kernel_sets[0];
#endif
    return inversion_guard ? set->guarded_gather : set->gather;
}

const char* gather_kernel_name(GatherFn fn)
{
    return kernels_of(fn).name;
}

} // namespace tethash::sim::detail
