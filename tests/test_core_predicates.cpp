// Exact orientation: sign against exact references (128-bit integers; Python fractions for arbitrary doubles).
#include "support.hpp"
#include "tethash/predicates.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

using namespace tethash::predicates;

namespace {

/// Exact sign of det[b−a, c−a, d−a] for integer coordinates (|difference| < 2^40).
__extension__ typedef __int128 i128;

int reference_sign(const std::int64_t* a, const std::int64_t* b, const std::int64_t* c, const std::int64_t* d)
{
    i128 u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    const i128 det =
        u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
    return (det > 0) - (det < 0);
}

} // namespace

TEST(CorePredicates, UnitTetOrientation)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {0, 0, 1};
    EXPECT_EQ(orient3d(a, b, c, d).sign, 1);
    EXPECT_EQ(orient3d(b, a, c, d).sign, -1);
    EXPECT_DOUBLE_EQ(orient3d(a, b, c, d).value, 1.0);
    EXPECT_EQ(orient3d_exact(a, b, c, d).sign, 1);
    EXPECT_EQ(orient3d(a, b, c, a).sign, 0);
}

TEST(CorePredicates, NearCoplanarIntegerPointsMatchExactReference)
{
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<std::int64_t> small(-(1 << 19), 1 << 19), coef(-40, 40), bump(-1, 1);
    int exact_used = 0, zeros = 0;
    for (int it = 0; it < 20000; ++it) {
        std::int64_t p[4][3];
        const std::int64_t base =
            (it % 3 == 0) ? (std::int64_t{1} << 40) : (it % 3 == 1 ? -(std::int64_t{1} << 35) : 0);
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                p[k][j] = base + small(rng) / ((it % 7) + 1);
        // d on the plane of a, b, c (integer combination), then nudged by at most one unit.
        const std::int64_t s = coef(rng), t = coef(rng);
        for (int j = 0; j < 3; ++j)
            p[3][j] = p[0][j] + s * (p[1][j] - p[0][j]) + t * (p[2][j] - p[0][j]) + bump(rng);
        double q[4][3];
        const double scale = std::ldexp(1.0, static_cast<int>(it % 5) * 20 - 40); // powers of two keep the sign
        for (int k = 0; k < 4; ++k)
            for (int j = 0; j < 3; ++j)
                q[k][j] = static_cast<double>(p[k][j]) * scale;
        const int want = reference_sign(p[0], p[1], p[2], p[3]);
        const Orientation o = orient3d(q[0], q[1], q[2], q[3]);
        ASSERT_EQ(o.sign, want) << "case " << it;
        ASSERT_EQ(orient3d_exact(q[0], q[1], q[2], q[3]).sign, want) << "case " << it;
        ASSERT_EQ(orient3d(q[1], q[0], q[2], q[3]).sign, -want) << "case " << it;
        exact_used += o.exact;
        zeros += want == 0;
    }
    EXPECT_GT(exact_used, 300); // the cases really are near-degenerate
    EXPECT_GT(zeros, 100);
}

TEST(CorePredicates, ArbitraryDoublesMatchPythonFractions)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "fractions");
    const auto dir = tethash::test::temp_dir();
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::ostringstream cases;
    std::vector<int> got;
    for (int it = 0; it < 600; ++it) {
        double q[4][3];
        const double off = it % 2 ? 1e6 : 0.0;
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                q[k][j] = off + u(rng);
        // d = a + s(b − a) + t(c − a) in floating point: on the plane up to rounding, the hardest case.
        const double s = u(rng), t = u(rng);
        for (int j = 0; j < 3; ++j)
            q[3][j] = q[0][j] + s * (q[1][j] - q[0][j]) + t * (q[2][j] - q[0][j]);
        if (it % 5 == 0) q[3][it % 3] = std::nextafter(q[3][it % 3], 2e6);
        char buf[64];
        for (int k = 0; k < 4; ++k)
            for (int j = 0; j < 3; ++j) {
                std::snprintf(buf, sizeof buf, "%.17g ", q[k][j]);
                cases << buf;
            }
        cases << "\n";
        got.push_back(orient3d(q[0], q[1], q[2], q[3]).sign);
    }
    tethash::test::write_text(dir / "cases.txt", cases.str());
    tethash::test::write_text(
        dir / "ref.py",
        "import sys\nfrom fractions import Fraction as F\n"
        "for line in open(sys.argv[1]):\n"
        "    v=[F(float(x)) for x in line.split()]\n"
        "    a,b,c,d=v[0:3],v[3:6],v[6:9],v[9:12]\n"
        "    u=[b[i]-a[i] for i in range(3)]; w=[c[i]-a[i] for i in range(3)]; z=[d[i]-a[i] for i in range(3)]\n"
        "    det=u[0]*(w[1]*z[2]-w[2]*z[1])-u[1]*(w[0]*z[2]-w[2]*z[0])+u[2]*(w[0]*z[1]-w[1]*z[0])\n"
        "    print((det>0)-(det<0))\n");
    const auto r = tethash::test::run_shell(py + " " + tethash::test::quote(dir / "ref.py") + " " +
                                            tethash::test::quote(dir / "cases.txt"));
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream in(r.out);
    int nonzero = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        int want = 9;
        ASSERT_TRUE(in >> want);
        EXPECT_EQ(got[i], want) << "case " << i;
        nonzero += want != 0;
    }
    EXPECT_GT(nonzero, 0);
}

TEST(CorePredicates, InsideTetClosedOnFacesEdgesCorners)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {0, 0, 1};
    const double pts[][3] = {{0.25, 0.25, 0.25},    {0, 0, 0},     {0.5, 0, 0},
                             {1.0 / 3, 1.0 / 3, 0}, {0.5, 0.5, 0}, {0.25, 0.25, 0.5}};
    for (const auto& p : pts) {
        const InsideResult r = inside_tet(p, a, b, c, d);
        EXPECT_TRUE(r.inside) << p[0] << " " << p[1] << " " << p[2];
        EXPECT_NEAR(r.bary[0] + r.bary[1] + r.bary[2] + r.bary[3], 1.0, 1e-12);
    }
    const double edge[3] = {0.5, 0, 0};
    const InsideResult r = inside_tet(edge, a, b, c, d);
    EXPECT_EQ(r.bary[2], 0.0); // exactly zero on the faces through the edge
    EXPECT_EQ(r.bary[3], 0.0);
    const double on[3] = {0.5, 0.25, 0.25}, out1[3] = {0.5, 0.5, std::nextafter(0.0, 1.0) * 1e200},
                 out2[3] = {-1e-300, 0.2, 0.2}, out3[3] = {0.5, 0.5, 1e-17};
    EXPECT_TRUE(inside_tet(on, a, b, c, d).inside);    // exactly on the slanted face x + y + z = 1
    EXPECT_FALSE(inside_tet(out1, a, b, c, d).inside); // beyond it by 5e-124: decided exactly
    EXPECT_FALSE(inside_tet(out2, a, b, c, d).inside);
    EXPECT_FALSE(inside_tet(out3, a, b, c, d).inside); // just beyond the slanted face x + y + z = 1
    // Degenerate (flat) tet: nothing inside, not even its own plane.
    const double flat[3] = {1, 1, 0};
    const InsideResult f = inside_tet(a, b, c, flat, edge);
    EXPECT_TRUE(f.degenerate);
    EXPECT_FALSE(f.inside);
}
