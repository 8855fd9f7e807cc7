// Exact orientation by a floating-point filter plus expansion arithmetic (Shewchuk 1997:
// nonoverlapping expansions, error-free sums and products). Written for tethash.
#include "tethash/predicates.hpp"

#include <cmath>

namespace tethash::predicates {
namespace {

/// A nonoverlapping expansion, components in increasing magnitude, zeros eliminated.
template <int N> struct Expansion {
    double c[N];
    int n = 0;
};

inline void two_sum(double a, double b, double& s, double& e)
{
    s = a + b;
    const double bv = s - a;
    const double av = s - bv;
    e = (a - av) + (b - bv);
}

inline void fast_two_sum(double a, double b, double& s, double& e) // requires |a| ≥ |b| or a == 0
{
    s = a + b;
    e = b - (s - a);
}

inline void two_diff(double a, double b, double& s, double& e)
{
    s = a - b;
    const double bv = a - s;
    const double av = s + bv;
    e = (a - av) + (bv - b);
}

inline void two_product(double a, double b, double& p, double& e)
{
    p = a * b;
    e = std::fma(a, b, -p);
}

/// out = e + b (Shewchuk's grow_expansion_zeroelim).
template <int N, int M> void grow(const Expansion<M>& e, double b, Expansion<N>& out)
{
    double q = b;
    out.n = 0;
    for (int i = 0; i < e.n; ++i) {
        double s, h;
        two_sum(q, e.c[i], s, h);
        q = s;
        if (h != 0.0) out.c[out.n++] = h;
    }
    if (q != 0.0 || out.n == 0) out.c[out.n++] = q;
}

/// out = e + f by repeated growth (O(mn); only on the rare exact path).
template <int N, int M, int K> void add(const Expansion<M>& e, const Expansion<K>& f, Expansion<N>& out)
{
    static_assert(N >= M + K);
    Expansion<N> tmp;
    out.n = 0;
    for (int i = 0; i < e.n; ++i)
        out.c[out.n++] = e.c[i];
    for (int j = 0; j < f.n; ++j) {
        grow(out, f.c[j], tmp);
        out.n = tmp.n;
        for (int i = 0; i < tmp.n; ++i)
            out.c[i] = tmp.c[i];
    }
    if (out.n == 0) out.c[out.n++] = 0.0;
}

/// out = e · b (Shewchuk's scale_expansion_zeroelim).
template <int N, int M> void scale(const Expansion<M>& e, double b, Expansion<N>& out)
{
    static_assert(N >= 2 * M);
    out.n = 0;
    double q, h;
    two_product(e.c[0], b, q, h);
    if (h != 0.0) out.c[out.n++] = h;
    for (int i = 1; i < e.n; ++i) {
        double p1, p0, sum;
        two_product(e.c[i], b, p1, p0);
        two_sum(q, p0, sum, h);
        if (h != 0.0) out.c[out.n++] = h;
        fast_two_sum(p1, sum, q, h);
        if (h != 0.0) out.c[out.n++] = h;
    }
    if (q != 0.0 || out.n == 0) out.c[out.n++] = q;
}

/// out = e · f.
template <int N, int M, int K> void multiply(const Expansion<M>& e, const Expansion<K>& f, Expansion<N>& out)
{
    static_assert(N >= 2 * M * K);
    out.n = 1;
    out.c[0] = 0.0;
    Expansion<2 * M> part;
    Expansion<N> tmp;
    for (int j = 0; j < f.n; ++j) {
        scale(e, f.c[j], part);
        tmp.n = 0;
        for (int i = 0; i < out.n; ++i)
            tmp.c[tmp.n++] = out.c[i];
        for (int i = 0; i < part.n; ++i) {
            Expansion<N> g;
            grow(tmp, part.c[i], g);
            tmp = g;
        }
        out = tmp;
    }
}

template <int M> Expansion<M> negate(Expansion<M> e)
{
    for (int i = 0; i < e.n; ++i)
        e.c[i] = -e.c[i];
    return e;
}

template <int M> int sign_of(const Expansion<M>& e)
{
    const double top = e.c[e.n - 1];
    return (top > 0) - (top < 0);
}

template <int M> double estimate(const Expansion<M>& e)
{
    double s = 0;
    for (int i = 0; i < e.n; ++i)
        s += e.c[i];
    return s;
}

inline Expansion<2> diff(double a, double b)
{
    Expansion<2> r;
    double s, e;
    two_diff(a, b, s, e);
    r.n = 0;
    if (e != 0.0) r.c[r.n++] = e;
    if (s != 0.0 || r.n == 0) r.c[r.n++] = s;
    return r;
}

} // namespace

Orientation orient3d_exact(const double* a, const double* b, const double* c, const double* d)
{
    const Expansion<2> adx = diff(a[0], d[0]), ady = diff(a[1], d[1]), adz = diff(a[2], d[2]);
    const Expansion<2> bdx = diff(b[0], d[0]), bdy = diff(b[1], d[1]), bdz = diff(b[2], d[2]);
    const Expansion<2> cdx = diff(c[0], d[0]), cdy = diff(c[1], d[1]), cdz = diff(c[2], d[2]);
    // n = (c − d) × (b − d), each component a difference of two products of 2-expansions.
    auto cross = [](const Expansion<2>& p, const Expansion<2>& q, const Expansion<2>& r, const Expansion<2>& s) {
        Expansion<8> t1, t2;
        multiply(p, q, t1);
        multiply(r, s, t2);
        Expansion<16> out;
        add(t1, negate(t2), out);
        return out;
    };
    const Expansion<16> nx = cross(cdy, bdz, cdz, bdy);
    const Expansion<16> ny = cross(cdz, bdx, cdx, bdz);
    const Expansion<16> nz = cross(cdx, bdy, cdy, bdx);
    Expansion<64> tx, ty, tz;
    multiply(nx, adx, tx);
    multiply(ny, ady, ty);
    multiply(nz, adz, tz);
    Expansion<128> txy;
    add(tx, ty, txy);
    Expansion<192> det;
    add(txy, tz, det);
    Orientation o;
    o.sign = sign_of(det);
    o.value = o.sign == 0 ? 0.0 : estimate(det);
    o.exact = true;
    return o;
}

Orientation orient3d(const double* a, const double* b, const double* c, const double* d)
{
    const double adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
    const double bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
    const double cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
    const double nx = cdy * bdz - cdz * bdy;
    const double ny = cdz * bdx - cdx * bdz;
    const double nz = cdx * bdy - cdy * bdx;
    const double det = adx * nx + ady * ny + adz * nz;
    const double permanent = std::fabs(adx) * (std::fabs(cdy * bdz) + std::fabs(cdz * bdy)) +
                             std::fabs(ady) * (std::fabs(cdz * bdx) + std::fabs(cdx * bdz)) +
                             std::fabs(adz) * (std::fabs(cdx * bdy) + std::fabs(cdy * bdx));
    const double bound = orient3d_error_bound * permanent;
    if (det > bound) return {1, det, false};
    if (-det > bound) return {-1, det, false};
    return orient3d_exact(a, b, c, d);
}

InsideResult inside_tet(const double* p, const double* a, const double* b, const double* c, const double* d)
{
    InsideResult r;
    const Orientation o = orient3d(a, b, c, d);
    r.exact_evaluations += o.exact;
    if (o.sign == 0) {
        r.degenerate = true;
        return r;
    }
    const Orientation f[4] = {orient3d(p, b, c, d), orient3d(a, p, c, d), orient3d(a, b, p, d), orient3d(a, b, c, p)};
    double sum = 0;
    for (const Orientation& fi : f) {
        r.exact_evaluations += fi.exact;
        if (fi.sign == -o.sign) return r;
        sum += fi.value;
    }
    r.inside = true;
    for (int i = 0; i < 4; ++i)
        r.bary[i] = f[i].sign == 0 ? 0.0 : f[i].value / sum;
    return r;
}

} // namespace tethash::predicates
