// The block-descent gather (src/sim/vertex_stencils.hpp): per lane, force and Hessian of the springs and volume
// terms, checked against finite differences of the energy; padding contributes nothing; the run-time kernel
// (AVX2 where present) agrees with the one-lane version.
#include "../src/sim/vertex_stencils.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace tethash::sim::detail;

namespace {

/// Four lanes (vertices 0 … 3) over 16 vertices: lane l has 3 − l / 2 springs and 4 − l volume terms; lane 3 is
/// padding when `lanes` is 3. Every spring is stretched (so the clamped Hessian is the exact one).
struct Stencils {
    std::vector<double> x;
    LaneGroup g{};
    std::vector<SpringLanes> springs;
    std::vector<TetLanes> tets;

    Stencils(unsigned seed, int lanes)
    {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(-1, 1);
        x.resize(3 * 16);
        for (double& c : x)
            c = u(rng);
        g.lanes = lanes;
        for (int l = 0; l < 4; ++l) {
            g.vertex[l] = l < lanes ? l : 0;
            g.damping[l] = 0;
        }
        g.spring_begin = 0;
        g.spring_end = 3;
        g.tet_begin = 0;
        g.tet_end = 4;
        springs.resize(3);
        tets.resize(4);
        for (int l = 0; l < 4; ++l) {
            const int own = g.vertex[l];
            for (int e = 0; e < 3; ++e) {
                SpringLanes& s = springs[static_cast<std::size_t>(e)];
                s.other[l] = own;
                s.rest[l] = 0;
                s.k[l] = s.stretch_t[l] = 0;
                if (l >= lanes || e >= 3 - l / 2) continue;
                s.other[l] = 4 + 3 * l + e;
                s.k[l] = 10.0 * (1 + e + l);
                s.rest[l] = 0.3 * length(own, s.other[l]);
                s.stretch_t[l] = 0; // damping relative to the rest length
            }
            for (int e = 0; e < 4; ++e) {
                TetLanes& t = tets[static_cast<std::size_t>(e)];
                t.a[l] = t.b[l] = t.c[l] = own;
                t.w0[l] = 0;
                t.k36[l] = t.excess_t[l] = 0;
                t.guard[l] = 0;
                if (l >= lanes || e >= 4 - l) continue;
                t.guard[l] = 0.02F * static_cast<float>(e + 1);
                t.a[l] = 4 + (l + e) % 12;
                t.b[l] = 4 + (l + e + 5) % 12;
                t.c[l] = 4 + (l + 2 * e + 9) % 12;
                t.k36[l] = 3.0 + e;
                t.w0[l] = 0.1 * (e + 1);
                t.excess_t[l] = 0; // damping relative to the rest volume
            }
        }
    }
    double length(int i, int j) const
    {
        double s = 0;
        for (int r = 0; r < 3; ++r)
            s += (x[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(r)] -
                  x[3 * static_cast<std::size_t>(j) + static_cast<std::size_t>(r)]) *
                 (x[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(r)] -
                  x[3 * static_cast<std::size_t>(j) + static_cast<std::size_t>(r)]);
        return std::sqrt(s);
    }
    /// The energy of lane l's terms (springs ½ k (l − L0)², volume terms ½ k36 (W − W0)²).
    double energy(int l) const
    {
        const int i = g.vertex[l];
        double e = 0;
        for (const SpringLanes& s : springs)
            if (s.k[l] != 0) e += 0.5 * s.k[l] * std::pow(length(i, s.other[l]) - s.rest[l], 2);
        for (const TetLanes& t : tets) {
            if (t.k36[l] == 0) continue;
            const double wl = w(l, t);
            e += 0.5 * t.k36[l] * (wl - t.w0[l]) * (wl - t.w0[l]);
        }
        return e;
    }
    /// W = 6V of lane l's volume entry e (W = (a − p) · ((b − a) × (c − a))), and its face normal |N|.
    double w(int l, const TetLanes& t, double* n_norm = nullptr) const
    {
        const double* p = x.data() + 3 * g.vertex[l];
        const double* a = x.data() + 3 * t.a[l];
        const double* b = x.data() + 3 * t.b[l];
        const double* c = x.data() + 3 * t.c[l];
        const double ba[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double ca[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {ba[1] * ca[2] - ba[2] * ca[1], ba[2] * ca[0] - ba[0] * ca[2],
                             ba[0] * ca[1] - ba[1] * ca[0]};
        if (n_norm) *n_norm = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        return (a[0] - p[0]) * n[0] + (a[1] - p[1]) * n[1] + (a[2] - p[2]) * n[2];
    }
    /// The kernels read positions with a stride of 4 doubles, 32-byte aligned.
    struct alignas(32) P4 {
        double c[4];
    };
    std::vector<P4> x4() const
    {
        std::vector<P4> out(x.size() / 3);
        for (std::size_t i = 0; i < out.size(); ++i)
            out[i] = {x[3 * i], x[3 * i + 1], x[3 * i + 2], 0.0};
        return out;
    }
    LaneTerms gather(GatherFn fn) const
    {
        const std::vector<P4> p = x4();
        LaneTerms out;
        fn(g, springs.data(), tets.data(), p.data()->c, 240.0, out);
        return out;
    }
};

GatherFn scalar_gather(bool inversion_guard = false)
{
    const char* old = std::getenv("TETHASH_SIMD");
    const std::string saved = old ? old : "";
    setenv("TETHASH_SIMD", "scalar", 1);
    GatherFn fn = choose_gather(inversion_guard);
    if (old)
        setenv("TETHASH_SIMD", saved.c_str(), 1);
    else
        unsetenv("TETHASH_SIMD");
    return fn;
}

constexpr int sym[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};

} // namespace

TEST(SimVertexStencils, ForceAndHessianAreTheEnergysDerivativesInEveryLane)
{
    for (GatherFn fn : {scalar_gather(), choose_gather()})
        for (unsigned seed = 1; seed <= 5; ++seed) {
            Stencils s(seed, 4);
            const LaneTerms t = s.gather(fn);
            for (int l = 0; l < 4; ++l) {
                const std::size_t i = static_cast<std::size_t>(s.g.vertex[l]);
                const double h = 1e-6;
                for (int r = 0; r < 3; ++r) {
                    const double keep = s.x[3 * i + static_cast<std::size_t>(r)];
                    s.x[3 * i + static_cast<std::size_t>(r)] = keep + h;
                    const double ep = s.energy(l);
                    const LaneTerms tp = s.gather(fn);
                    s.x[3 * i + static_cast<std::size_t>(r)] = keep - h;
                    const double em = s.energy(l);
                    const LaneTerms tm = s.gather(fn);
                    s.x[3 * i + static_cast<std::size_t>(r)] = keep;
                    const double grad = (ep - em) / (2 * h);
                    EXPECT_NEAR(t.f[r][l], -grad, 1e-5 * (1 + std::fabs(grad)))
                        << gather_kernel_name(fn) << " seed " << seed << " lane " << l << " axis " << r;
                    for (int q = 0; q < 3; ++q) {
                        const double hess = -(tp.f[q][l] - tm.f[q][l]) / (2 * h);
                        EXPECT_NEAR(t.H[sym[q][r]][l], hess, 1e-5 * (1 + std::fabs(hess)))
                            << gather_kernel_name(fn) << " seed " << seed << " lane " << l << " H(" << q << "," << r
                            << ")";
                    }
                }
            }
        }
}

TEST(SimVertexStencils, PaddingLanesAndEntriesContributeNothing)
{
    for (GatherFn fn : {scalar_gather(), choose_gather()}) {
        // Lane 3 is padding in the second group: lanes 0 … 2 must not change. (Padding entries, fewer springs
        // and tets in a lane than in its group, are in every lane but 0 of the derivative test above.)
        Stencils full(7, 4), three(7, 3);
        const LaneTerms a = full.gather(fn), b = three.gather(fn);
        for (int l = 0; l < 3; ++l)
            for (int r = 0; r < 3; ++r)
                EXPECT_DOUBLE_EQ(a.f[r][l], b.f[r][l]) << gather_kernel_name(fn) << " lane " << l;
        // A zero-length spring (coincident ends) is skipped, not a NaN.
        Stencils coincident(8, 4);
        for (int r = 0; r < 3; ++r)
            coincident.x[3 * 4 + static_cast<std::size_t>(r)] = coincident.x[static_cast<std::size_t>(r)];
        const LaneTerms c = coincident.gather(fn);
        for (int r = 0; r < 3; ++r)
            EXPECT_TRUE(std::isfinite(c.f[r][0])) << gather_kernel_name(fn);
        for (int r = 0; r < 6; ++r)
            EXPECT_TRUE(std::isfinite(c.H[r][0])) << gather_kernel_name(fn);
    }
}

TEST(SimVertexStencils, RunTimeKernelAgreesWithTheOneLaneVersionWithDamping)
{
    GatherFn fast = choose_gather(), slow = scalar_gather();
    const char* env = std::getenv("TETHASH_SIMD");
    if (env && std::strcmp(env, "scalar") == 0) {
        EXPECT_STREQ(gather_kernel_name(fast), "scalar");
    }
    for (unsigned seed = 11; seed <= 20; ++seed) {
        Stencils s(seed, 4);
        for (int l = 0; l < 4; ++l)
            s.g.damping[l] = 0.01 * (l + 1);
        // Compressed springs and moved volumes: the clamp and the damping terms are exercised.
        for (SpringLanes& sp : s.springs)
            for (int l = 0; l < 4; ++l) {
                sp.rest[l] *= 5;
                sp.stretch_t[l] = static_cast<float>(-0.1 * sp.rest[l]);
            }
        for (TetLanes& t : s.tets)
            for (int l = 0; l < 4; ++l)
                t.excess_t[l] = static_cast<float>(t.w0[l]);
        const LaneTerms a = s.gather(fast), b = s.gather(slow);
        for (int l = 0; l < 4; ++l) {
            for (int r = 0; r < 3; ++r)
                EXPECT_NEAR(a.f[r][l], b.f[r][l], 1e-12 * (1 + std::fabs(b.f[r][l]))) << "seed " << seed;
            for (int r = 0; r < 6; ++r)
                EXPECT_NEAR(a.H[r][l], b.H[r][l], 1e-12 * (1 + std::fabs(b.H[r][l]))) << "seed " << seed;
        }
    }
}

TEST(SimVertexStencils, SolveGivesHdEqualsFAndFlagsLanesThatAreNotPositiveDefinite)
{
    for (GatherFn fn : {scalar_gather(), choose_gather()}) {
        const SolveFn solve = choose_solve(fn);
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> u(-1, 1);
        for (int round = 0; round < 20; ++round) {
            LaneTerms t;
            double A[4][3][3];
            for (int l = 0; l < 4; ++l) {
                // H = B Bᵀ + 0.1 I (positive definite), except lane 2 every other round: an indefinite matrix.
                double B[3][3];
                for (auto& row : B)
                    for (double& v : row)
                        v = u(rng);
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) {
                        A[l][i][j] = (i == j ? 0.1 : 0.0);
                        for (int k = 0; k < 3; ++k)
                            A[l][i][j] += B[i][k] * B[j][k];
                    }
                if (l == 2 && round % 2) A[l][1][1] = -1;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        t.H[sym[i][j]][l] = A[l][i][j];
                for (int r = 0; r < 3; ++r)
                    t.f[r][l] = u(rng);
            }
            double d[3][4];
            const int solved = solve(t, d);
            for (int l = 0; l < 4; ++l) {
                const bool indefinite = l == 2 && round % 2;
                EXPECT_EQ((solved >> l) & 1, indefinite ? 0 : 1) << gather_kernel_name(fn) << " lane " << l;
                if (indefinite) continue;
                for (int i = 0; i < 3; ++i) {
                    double hd = 0;
                    for (int j = 0; j < 3; ++j)
                        hd += A[l][i][j] * d[j][l];
                    EXPECT_NEAR(hd, t.f[i][l], 1e-9) << gather_kernel_name(fn) << " lane " << l;
                }
            }
        }
    }
}

TEST(SimVertexStencils, StartOfSubstepLengthsAndVolumesMatchTheOneLaneVersion)
{
    GatherFn fast = choose_gather(), slow = scalar_gather();
    Stencils s(3, 4);
    struct alignas(32) P4 {
        double c[4];
    };
    std::vector<P4> x4(s.x.size() / 3);
    for (std::size_t i = 0; i < x4.size(); ++i)
        x4[i] = {s.x[3 * i], s.x[3 * i + 1], s.x[3 * i + 2], 0.0};
    std::vector<SpringLanes> sa = s.springs, sb = s.springs;
    std::vector<TetLanes> ta = s.tets, tb = s.tets;
    choose_start(fast)(s.g, sa.data(), ta.data(), x4.data()->c);
    choose_start(slow)(s.g, sb.data(), tb.data(), x4.data()->c);
    for (std::size_t e = 0; e < sa.size(); ++e)
        for (int l = 0; l < 4; ++l) {
            // Kept in single precision: length − rest rounded to the nearest float, in both kernels.
            const double stretch = s.length(s.g.vertex[l], sa[e].other[l]) - sa[e].rest[l];
            EXPECT_NEAR(sa[e].stretch_t[l], stretch, 1e-14 + 0x1p-24 * std::fabs(stretch));
            EXPECT_NEAR(sb[e].stretch_t[l], stretch, 1e-14 + 0x1p-24 * std::fabs(stretch));
        }
    for (std::size_t e = 0; e < ta.size(); ++e)
        for (int l = 0; l < 4; ++l) {
            // W = 6 V = (x_a − x_i) · ((x_b − x_a) × (x_c − x_a)), written out here as a determinant.
            const auto X = [&](std::int32_t v, int r) { return s.x[3 * static_cast<std::size_t>(v) + r]; };
            const std::int32_t i = s.g.vertex[l], a = ta[e].a[l], b = ta[e].b[l], c = ta[e].c[l];
            double m[3][3];
            for (int r = 0; r < 3; ++r) {
                m[0][r] = X(a, r) - X(i, r);
                m[1][r] = X(b, r) - X(a, r);
                m[2][r] = X(c, r) - X(a, r);
            }
            const double w = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                             m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            const double excess = w - ta[e].w0[l];
            EXPECT_NEAR(ta[e].excess_t[l], excess, 1e-13 + 0x1p-24 * std::fabs(excess))
                << "entry " << e << " lane " << l;
            EXPECT_NEAR(tb[e].excess_t[l], excess, 1e-13 + 0x1p-24 * std::fabs(excess))
                << "entry " << e << " lane " << l;
        }
}

TEST(SimVertexStencils, InversionGuardLowersNoTetBelowItsFloor)
{
    // reach2 is min over a lane's guarded entries with W > 0 of ((W − τ)⁺ / |N|)² in both kernels; a step scaled by
    // guarded_fraction lowers no such entry by more than 0.9 (W − τ)⁺ (W is linear in the lane's vertex), and a step
    // shorter than 0.9 × reach needs no scaling.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    int shortened = 0, steps = 0;
    for (unsigned seed = 1; seed <= 60; ++seed) {
        Stencils s(seed, 4);
        for (const bool scalar : {false, true}) {
            const GatherFn fn = scalar ? scalar_gather(true) : choose_gather(true);
            const LaneTerms t = s.gather(fn);
            // The gather without the guard (the default path) gives the same terms and no reach.
            const LaneTerms plain = s.gather(scalar ? scalar_gather() : choose_gather());
            for (int l = 0; l < 4; ++l) {
                for (int r = 0; r < 3; ++r)
                    EXPECT_EQ(plain.f[r][l], t.f[r][l]) << gather_kernel_name(fn) << " seed " << seed;
                for (int r = 0; r < 6; ++r)
                    EXPECT_EQ(plain.H[r][l], t.H[r][l]) << gather_kernel_name(fn) << " seed " << seed;
            }
            for (int l = 0; l < 4; ++l) {
                EXPECT_TRUE(std::isinf(plain.reach2[l])) << gather_kernel_name(fn) << " seed " << seed;
                double expect = std::numeric_limits<double>::infinity();
                for (const TetLanes& e : s.tets) {
                    double n = 0;
                    const double w = s.w(l, e, &n);
                    if (e.guard[l] > 0 && w > 0)
                        expect = std::min(expect, std::pow(std::max(0.0, w - e.guard[l]) / n, 2));
                }
                if (std::isinf(expect)) {
                    EXPECT_TRUE(std::isinf(t.reach2[l])) << gather_kernel_name(fn) << " seed " << seed;
                } else {
                    EXPECT_NEAR(t.reach2[l], expect, 1e-9 * expect) << gather_kernel_name(fn) << " seed " << seed;
                }
            }
        }
        const LaneTerms t = s.gather(scalar_gather(true));
        for (int l = 0; l < 4; ++l) {
            const double len = 2 * (u(rng) + 1);
            double d[3] = {u(rng), u(rng), u(rng)};
            const double dn = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (double& c : d)
                c *= len / dn;
            const std::vector<Stencils::P4> p = s.x4();
            const double f = guarded_fraction(s.g, s.tets.data(), l, p.data()->c, d);
            ASSERT_GE(f, 0.0);
            ASSERT_LE(f, 1.0);
            if (len < 0.9 * std::sqrt(t.reach2[l])) {
                EXPECT_EQ(f, 1.0) << "seed " << seed << " lane " << l;
            }
            ++steps;
            shortened += f < 1 ? 1 : 0;
            Stencils moved = s;
            for (int r = 0; r < 3; ++r)
                moved.x[3 * static_cast<std::size_t>(s.g.vertex[l]) + static_cast<std::size_t>(r)] += f * d[r];
            for (const TetLanes& e : s.tets) {
                const double before = s.w(l, e), after = moved.w(l, e);
                if (!(e.guard[l] > 0) || !(before > 0)) continue;
                EXPECT_GE(after, before - 0.9 * std::max(0.0, before - e.guard[l]) - 1e-12)
                    << "seed " << seed << " lane " << l;
                EXPECT_GT(after, 0) << "seed " << seed << " lane " << l;
            }
        }
    }
    EXPECT_GT(shortened, steps / 10); // the guard acted (random steps of up to 4 against tets of size ~1)
    EXPECT_LT(shortened, steps);      // and not on every step
}
