// Continuous queries (tethash/ccd.hpp): the degenerate cases by hand, for both query types; queries built to meet
// at a known time (exactly, in dyadic coordinates) must be reported no later; queries whose sampled distance proves
// a miss wider than the tolerance must not be; random small-integer queries checked exactly at sample times.
#include "support.hpp"
#include "tethash/ccd.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace tethash;
using namespace tethash::ccd;
using V = Eigen::Vector3d;

namespace {

/// A query: 4 corners at t = 0 and 4 at t = 1 (vertex-face: p, a, b, c; edge-edge: ea0, ea1, eb0, eb1).
struct Query {
    std::array<V, 4> start, end;
};

CcdResult vf(const Query& q, const CcdParams& params = {})
{
    return vertex_face_ccd(q.start[0], q.start[1], q.start[2], q.start[3], q.end[0], q.end[1], q.end[2], q.end[3],
                           params);
}
CcdResult ee(const Query& q, const CcdParams& params = {})
{
    return edge_edge_ccd(q.start[0], q.start[1], q.start[2], q.start[3], q.end[0], q.end[1], q.end[2], q.end[3],
                         params);
}

/// A query whose corners do not move.
Query still(const V& x0, const V& x1, const V& x2, const V& x3)
{
    return {{x0, x1, x2, x3}, {x0, x1, x2, x3}};
}

/// The triangle (0,0,0), (1,0,0), (0,1,0) fixed, the vertex moving from p0 to p1.
Query vertex_moves(const V& p0, const V& p1)
{
    const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    return {{p0, a, b, c}, {p1, a, b, c}};
}

/// Edge a from (0,0,0) to (1,0,0) fixed, edge b moving from (b0, b1) to (b0 + d, b1 + d).
Query edge_moves(const V& b0, const V& b1, const V& d)
{
    const V a0(0, 0, 0), a1(1, 0, 0);
    return {{a0, a1, b0, b1}, {a0, a1, b0 + d, b1 + d}};
}

void expect_hit(const CcdResult& r, double first_contact, const char* what)
{
    EXPECT_TRUE(r.hit) << what;
    if (!r.hit) return;
    EXPECT_LE(r.toi, first_contact) << what;
    EXPECT_GE(r.toi, first_contact - 1e-4) << what << " (" << outcome_name(r.outcome) << ")";
    EXPECT_GE(r.toi, 0.0) << what;
}

void expect_miss(const CcdResult& r, const char* what)
{
    EXPECT_FALSE(r.hit) << what << ": toi " << r.toi << " (" << outcome_name(r.outcome) << ")";
}

} // namespace

TEST(CoreCcd, VertexFaceDegenerateCasesAreHits)
{
    expect_hit(vf(vertex_moves({0.2, 0.2, 1}, {0.2, 0.2, -1})), 0.5, "through the face");
    expect_hit(vf(vertex_moves({0.2, 0.2, 0}, {0.2, 0.2, 1})), 0.0, "on the face at t = 0, leaving");
    expect_hit(vf(vertex_moves({0.2, 0.2, 1}, {0.2, 0.2, 0})), 1.0, "reaching the face at t = 1");
    expect_hit(vf(vertex_moves({0.2, 0.2, 0}, {0.2, 0.2, 0})), 0.0, "on the face, no motion");
    expect_hit(vf(vertex_moves({-1, 0.25, 0}, {1, 0.25, 0})), 0.5, "coplanar motion entering at t = 0.5");
    expect_hit(vf(vertex_moves({0.1, 0.1, 0}, {0.6, 0.3, 0})), 0.0, "sliding on the face");
    expect_hit(vf(vertex_moves({0.1, 0, 0}, {0.9, 0, 0})), 0.0, "sliding along an edge");
    expect_hit(vf(vertex_moves({-1, 0, 0}, {3, 0, 0})), 0.25, "along the edge's line, entering at a corner");
    expect_hit(vf(vertex_moves({0, 0, 1}, {0, 0, -1})), 0.5, "through a corner");
    expect_hit(vf(vertex_moves({0.5, 0.5, 1}, {0.5, 0.5, -1})), 0.5, "through the middle of the long edge");
    expect_hit(vf(vertex_moves({0.5, -1, 1}, {0.5, 1, -1})), 0.5, "across the edge's line at the edge");
    // The face moves onto a still vertex, and a face that flattens to a segment through the vertex.
    expect_hit(vf({{V(0.2, 0.2, 0), V(0, 0, 1), V(1, 0, 1), V(0, 1, 1)},
                   {V(0.2, 0.2, 0), V(0, 0, -1), V(1, 0, -1), V(0, 1, -1)}}),
               0.5, "the face moving onto the vertex");
    expect_hit(vf(still({0.5, 0, 0}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0})), 0.0, "on a degenerate (collinear) face");
    expect_hit(vf({{V(0.3, 0.3, 0), V(0, 0, 0), V(1, 0, 0), V(0, 1, 1)},
                   {V(0.3, 0.3, 0), V(0, 0, 0), V(1, 0, 0), V(0, 1, -1)}}),
               0.5, "a face turning through the vertex");
    // Parallel motion in the face's plane, inside from the start, and at a corner at t = 1 exactly.
    expect_hit(vf(vertex_moves({0.2, 0.2, 0}, {0.3, 0.2, 0})), 0.0, "parallel motion in the plane");
    expect_hit(vf(vertex_moves({2, 2, 0}, {1, 0, 0})), 1.0, "reaching a corner at t = 1 in the plane");
}

TEST(CoreCcd, VertexFaceNearMissesAreMisses)
{
    expect_miss(vf(vertex_moves({0.2, 0.2, 0.1}, {0.6, 0.3, 0.1})), "parallel motion above the face");
    expect_miss(vf(vertex_moves({-0.1, 0.2, 0}, {-0.1, 0.9, 0})), "coplanar motion beside an edge");
    expect_miss(vf(vertex_moves({0.6, 0.6, 1}, {0.6, 0.6, -1})), "through the plane beyond the long edge");
    expect_miss(vf(vertex_moves({0.2, 0.2, 1}, {0.2, 0.2, 1e-3})), "stopping 1e-3 short");
    expect_miss(vf(vertex_moves({-1e-3, 0.5, 1}, {-1e-3, 0.5, -1})), "passing 1e-3 beside an edge");
    expect_miss(vf(still({0.2, 0.2, 1e-3}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0})), "no motion, 1e-3 above");
    const CcdResult far = vf(vertex_moves({5, 5, 5}, {6, 6, 6}));
    EXPECT_EQ(far.outcome, CcdOutcome::boxes_apart);
}

TEST(CoreCcd, EdgeEdgeDegenerateCasesAreHits)
{
    expect_hit(ee(edge_moves({0.5, -1, 1}, {0.5, 1, 1}, {0, 0, -2})), 0.5, "crossing edges");
    expect_hit(ee(edge_moves({0.5, -1, 0}, {0.5, 1, 0}, {0, 0, 1})), 0.0, "crossing at t = 0");
    expect_hit(ee(edge_moves({0.5, -1, 1}, {0.5, 1, 1}, {0, 0, -1})), 1.0, "crossing at t = 1");
    expect_hit(ee(edge_moves({0.5, -1, 0}, {0.5, 1, 0}, {0, 0, 0})), 0.0, "crossing, no motion");
    expect_hit(ee(edge_moves({0.2, 1, 0}, {0.8, 1, 0}, {0, -2, 0})), 0.5, "parallel edges meeting (coplanar)");
    expect_hit(ee(edge_moves({0.2, 1, 1}, {0.8, 1, 1}, {0, -2, -2})), 0.5, "parallel edges meeting, oblique");
    expect_hit(ee(edge_moves({0.5, 0, 0}, {2, 0, 0}, {0, 0, 0})), 0.0, "collinear overlap, no motion");
    expect_hit(ee(edge_moves({2, 0, 0}, {3, 0, 0}, {-4, 0, 0})), 0.25, "collinear, sliding into overlap");
    expect_hit(ee(edge_moves({1, 0, 1}, {1, 1, 1}, {0, 0, -2})), 0.5, "end on end");
    expect_hit(ee(edge_moves({0.5, 0.5, 1}, {0.5, 0.5, 1}, {0, -1, -2})), 0.5, "a zero-length edge crossing");
    expect_hit(ee(still({0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0})), 0.0, "two points, one place");
    expect_hit(ee(edge_moves({0.5, 0, 0}, {0.5, 1, 0}, {0.3, 0, 0})), 0.0, "sliding along the edge, touching");
}

TEST(CoreCcd, EdgeEdgeNearMissesAreMisses)
{
    expect_miss(ee(edge_moves({0.5, -1, 1e-3}, {0.5, 1, 1e-3}, {0.3, 0, 0})), "parallel motion 1e-3 above");
    expect_miss(ee(edge_moves({0.2, 1, 0}, {0.8, 1, 0}, {0, -0.999, 0})), "parallel edges stopping short");
    expect_miss(ee(edge_moves({1.001, -1, 1}, {1.001, 1, 1}, {0, 0, -2})), "crossing the line beyond the end");
    expect_miss(ee(edge_moves({1.5, 0, 0}, {2, 0, 0}, {0, 0, 0})), "collinear, apart, no motion");
    expect_miss(ee(edge_moves({1.5, 0, 0}, {2, 0, 0}, {-0.499, 0, 0})), "collinear, stopping short");
    const CcdResult never = ee(edge_moves({0.5, -1, -0.5}, {0.5, 1, 1.5}, {0, 0, 0.1})); // skew throughout
    EXPECT_FALSE(never.hit);
    EXPECT_EQ(never.outcome, CcdOutcome::never_coplanar);
}

TEST(CoreCcd, IterationCapReportsAContactNoLaterThanTheFirst)
{
    CcdParams capped;
    capped.max_iterations = 3;
    for (const CcdResult r : {vf(vertex_moves({0.2, 0.2, 1}, {0.2, 0.2, -1}), capped),
                              ee(edge_moves({0.5, -1, 1}, {0.5, 1, 1}, {0, 0, -2}), capped)}) {
        EXPECT_TRUE(r.hit);
        EXPECT_EQ(r.outcome, CcdOutcome::iteration_cap);
        EXPECT_LE(r.toi, 0.5);
        EXPECT_EQ(r.iterations, 3);
    }
}

TEST(CoreCcd, BadInputIsAnError)
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Query q = vertex_moves({0.2, 0.2, 1}, {0.2, 0.2, -1});
    test::expect_error(
        [&] {
            vertex_face_ccd(V(nan, 0, 0), q.start[1], q.start[2], q.start[3], q.end[0], q.end[1], q.end[2], q.end[3]);
        },
        {"vertex_face_ccd", "point 0", "not finite"});
    test::expect_error(
        [&] {
            edge_edge_ccd(q.start[0], q.start[1], q.start[2], q.start[3], q.end[0], q.end[1], q.end[2], V(0, 0, 1e60));
        },
        {"edge_edge_ccd", "point 7"});
    CcdParams bad;
    bad.tolerance = 0;
    test::expect_error([&] { vf(q, bad); }, {"tolerance"});
    bad = {};
    bad.max_iterations = 0;
    test::expect_error([&] { ee(q, bad); }, {"max_iterations"});
}

namespace {

/// Uniform integer in [lo, hi].
int uniform(std::mt19937_64& rng, int lo, int hi)
{
    return std::uniform_int_distribution<int>(lo, hi)(rng);
}

V random_grid_point(std::mt19937_64& rng, int range, double unit)
{
    return V(uniform(rng, -range, range), uniform(rng, -range, range), uniform(rng, -range, range)) * unit;
}

} // namespace

// Contacts built exactly at t = 1/2 in dyadic coordinates (every value below exact in doubles): the vertex at
// a face point with barycentric coordinates in quarters, or the two edges through one point at quarters of each.
TEST(CoreCcd, BuiltContactsAreFoundNoLater)
{
    std::mt19937_64 rng(20260);
    int queries = 0;
    for (int i = 0; i < 1500; ++i) {
        Query q;
        for (int c = 0; c < 4; ++c) {
            q.start[c] = random_grid_point(rng, 16, 1.0 / 16);
            q.end[c] = random_grid_point(rng, 16, 1.0 / 16);
        }
        std::array<V, 4> half;
        for (int c = 0; c < 4; ++c)
            half[c] = 0.5 * (q.start[c] + q.end[c]);
        const double u = uniform(rng, 0, 4) / 4.0, v = uniform(rng, 0, 4 - static_cast<int>(4 * u)) / 4.0;
        const bool edges = i % 2 == 1;
        if (!edges) {
            const V meet = half[1] + u * (half[2] - half[1]) + v * (half[3] - half[1]);
            q.end[0] = 2.0 * meet - q.start[0]; // the vertex at `meet` at t = 1/2
            const CcdResult r = vf(q);
            ASSERT_TRUE(r.hit) << "vertex-face query " << i;
            EXPECT_LE(r.toi, 0.5) << "vertex-face query " << i;
        } else {
            // Edge b's first end is placed so that edge b passes, at t = 1/2, through edge a's point at u.
            const V meet = half[0] + u * (half[1] - half[0]);
            const double w = uniform(rng, 0, 4) / 4.0;          // where along b the point lies
            const V b1_half = half[3];                          // b's second end at t = 1/2
            if (w == 1.0) continue;                             // b0 would be undetermined
            const V b0_half = (meet - w * b1_half) / (1.0 - w); // meet = (1 - w) b0 + w b1
            q.end[2] = 2.0 * b0_half - q.start[2];
            const CcdResult r = ee(q);
            ASSERT_TRUE(r.hit) << "edge-edge query " << i;
            EXPECT_LE(r.toi, 0.5) << "edge-edge query " << i;
        }
        ++queries;
    }
    EXPECT_GT(queries, 1000);
}

namespace {

/// Distance from x to the closed triangle (a, b, c) (double arithmetic; a degenerate triangle is its edges).
double point_triangle_distance(const V& x, const V& a, const V& b, const V& c);

double point_segment_distance(const V& x, const V& a, const V& b)
{
    const V d = b - a;
    const double len2 = d.squaredNorm();
    const double s = len2 > 0 ? std::clamp((x - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    return (x - (a + s * d)).norm();
}

double point_triangle_distance(const V& x, const V& a, const V& b, const V& c)
{
    double best =
        std::min({point_segment_distance(x, a, b), point_segment_distance(x, b, c), point_segment_distance(x, c, a)});
    const V n = (b - a).cross(c - a);
    if (n.squaredNorm() > 0) {
        const V y = x - n * ((x - a).dot(n) / n.squaredNorm()); // projection onto the plane
        const bool inside =
            (b - a).cross(y - a).dot(n) >= 0 && (c - b).cross(y - b).dot(n) >= 0 && (a - c).cross(y - c).dot(n) >= 0;
        if (inside) best = std::min(best, (x - y).norm());
    }
    return best;
}

/// Distance between closed segments (a0, a1) and (b0, b1), by the interior critical point and the four ends.
double segment_distance(const V& a0, const V& a1, const V& b0, const V& b1)
{
    double best = std::min({point_segment_distance(a0, b0, b1), point_segment_distance(a1, b0, b1),
                            point_segment_distance(b0, a0, a1), point_segment_distance(b1, a0, a1)});
    const V da = a1 - a0, db = b1 - b0, r = a0 - b0;
    const double aa = da.dot(da), bb = db.dot(db), ab = da.dot(db), ar = da.dot(r), br = db.dot(r);
    const double den = aa * bb - ab * ab;
    if (den > 1e-12 * aa * bb) {
        const double s = (ab * br - bb * ar) / den, t = (aa * br - ab * ar) / den;
        if (s > 0 && s < 1 && t > 0 && t < 1) best = std::min(best, (a0 + s * da - (b0 + t * db)).norm());
    }
    return best;
}

} // namespace

// Random queries, half of them near a contact: when the distance sampled at 2049 times stays above the largest
// change between two samples plus 1e-4 (a margin far above the 1e-6 tolerance), the primitives never meet within
// it, so a reported contact is a false positive; when a sample's distance is below 1e-12 they meet (within the
// rounding of the sample), so a missed contact is a false negative.
TEST(CoreCcd, RandomQueriesAgreeWithSampledDistance)
{
    std::mt19937_64 rng(4242);
    std::uniform_real_distribution<double> unit(-1, 1);
    const int samples = 2048;
    int proven_misses = 0, sampled_hits = 0;
    for (int i = 0; i < 1200; ++i) {
        const bool edges = i % 2 == 1;
        Query q;
        for (int c = 0; c < 4; ++c) {
            q.start[c] = V(unit(rng), unit(rng), unit(rng));
            q.end[c] = q.start[c] + 0.5 * V(unit(rng), unit(rng), unit(rng));
        }
        double speed = 0; // bound on the distance's change per unit t
        for (int c = 0; c < 4; ++c)
            speed = std::max(speed, (q.end[c] - q.start[c]).norm());
        speed *= 2;
        double least = std::numeric_limits<double>::infinity();
        for (int s = 0; s <= samples; ++s) {
            const double t = static_cast<double>(s) / samples;
            std::array<V, 4> x;
            for (int c = 0; c < 4; ++c)
                x[c] = q.start[c] + t * (q.end[c] - q.start[c]);
            least = std::min(least, edges ? segment_distance(x[0], x[1], x[2], x[3])
                                          : point_triangle_distance(x[0], x[1], x[2], x[3]));
        }
        const CcdResult r = edges ? ee(q) : vf(q);
        if (least > speed * 0.5 / samples + 1e-4) {
            ++proven_misses;
            EXPECT_FALSE(r.hit) << (edges ? "edge-edge" : "vertex-face") << " query " << i << ": sampled distance "
                                << least;
        }
        if (least < 1e-12) {
            ++sampled_hits;
            EXPECT_TRUE(r.hit) << (edges ? "edge-edge" : "vertex-face") << " query " << i;
        }
    }
    EXPECT_GT(proven_misses, 600);
}

// Small integer coordinates, sampled at t = k/64 where positions are exact: an exact contact at a sample (the
// vertex in the closed face, or the segments meeting, decided in 128-bit integers) must be reported no later.
TEST(CoreCcd, GridQueriesCheckedExactlyAtSamples)
{
    __extension__ typedef __int128 i128;
    using I3 = std::array<i128, 3>;
    const auto sub = [](const I3& a, const I3& b) { return I3{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
    const auto cross = [](const I3& a, const I3& b) {
        return I3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    const auto dot = [](const I3& a, const I3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const auto zero = [](const I3& a) { return a[0] == 0 && a[1] == 0 && a[2] == 0; };
    std::mt19937_64 rng(77);
    int contacts = 0;
    for (int i = 0; i < 4000; ++i) {
        const bool edges = i % 2 == 1;
        std::array<std::array<int, 3>, 8> g{};
        for (auto& p : g)
            for (int& c : p)
                c = uniform(rng, -2, 2);
        Query q;
        for (int c = 0; c < 4; ++c) {
            q.start[c] = V(g[c][0], g[c][1], g[c][2]);
            q.end[c] = V(g[4 + c][0], g[4 + c][1], g[4 + c][2]);
        }
        int first = -1; // first sample k with an exact contact at t = k / 64
        for (int k = 0; k <= 64 && first < 0; ++k) {
            std::array<I3, 4> x; // 64 × position at t = k / 64
            for (int c = 0; c < 4; ++c)
                for (int a = 0; a < 3; ++a)
                    x[c][a] = static_cast<i128>(64 - k) * g[c][a] + static_cast<i128>(k) * g[4 + c][a];
            if (!edges) {
                const I3 n = cross(sub(x[2], x[1]), sub(x[3], x[1]));
                if (zero(n) || dot(n, sub(x[0], x[1])) != 0) continue; // flat faces are left to other tests
                const bool inside = dot(cross(sub(x[2], x[1]), sub(x[0], x[1])), n) >= 0 &&
                                    dot(cross(sub(x[3], x[2]), sub(x[0], x[2])), n) >= 0 &&
                                    dot(cross(sub(x[1], x[3]), sub(x[0], x[3])), n) >= 0;
                if (inside) first = k;
            } else {
                const I3 da = sub(x[1], x[0]), db = sub(x[3], x[2]);
                const I3 n = cross(da, db);
                if (zero(n) || dot(n, sub(x[2], x[0])) != 0) continue; // parallel edges are left to other tests
                // Coplanar, not parallel: each segment's ends on opposite sides of (or on) the other's line.
                const i128 s0 = dot(cross(da, sub(x[2], x[0])), n), s1 = dot(cross(da, sub(x[3], x[0])), n);
                const i128 r0 = dot(cross(db, sub(x[0], x[2])), n), r1 = dot(cross(db, sub(x[1], x[2])), n);
                const auto sign = [](i128 v) { return (v > 0) - (v < 0); };
                if (sign(s0) * sign(s1) <= 0 && sign(r0) * sign(r1) <= 0) first = k;
            }
        }
        if (first < 0) continue;
        ++contacts;
        const CcdResult r = edges ? ee(q) : vf(q);
        ASSERT_TRUE(r.hit) << (edges ? "edge-edge" : "vertex-face") << " query " << i << ": contact at t = " << first
                           << "/64";
        EXPECT_LE(r.toi, first / 64.0) << (edges ? "edge-edge" : "vertex-face") << " query " << i;
    }
    EXPECT_GT(contacts, 300);
}

// Contacts built exactly at t = 1/2 with every point moving in the plane z = 0 (coplanar motion, where F's third
// coordinate is 0 throughout and only in-plane directions can drop boxes): found no later, and without reaching the
// iteration cap (which, without the in-plane exclusions, about one query in a thousand of these did).
TEST(CoreCcd, CoplanarMotionContactsAreFoundWithinTheCap)
{
    std::mt19937_64 rng(31);
    std::int64_t most = 0;
    for (int i = 0; i < 4000; ++i) {
        Query q;
        for (int c = 0; c < 4; ++c) {
            q.start[c] = random_grid_point(rng, 16, 1.0 / 16);
            q.end[c] = random_grid_point(rng, 16, 1.0 / 16);
            q.start[c].z() = 0;
            q.end[c].z() = 0;
        }
        std::array<V, 4> half;
        for (int c = 0; c < 4; ++c)
            half[c] = 0.5 * (q.start[c] + q.end[c]);
        const double u = uniform(rng, 0, 4) / 4.0, v = uniform(rng, 0, 4 - static_cast<int>(4 * u)) / 4.0;
        CcdResult r;
        if (i % 2 == 0) {
            q.end[0] = 2.0 * (half[1] + u * (half[2] - half[1]) + v * (half[3] - half[1])) - q.start[0];
            r = vf(q);
        } else {
            const V meet = half[0] + u * (half[1] - half[0]);
            const double w = 0.25 * uniform(rng, 0, 3);
            q.end[2] = 2.0 * ((meet - w * half[3]) / (1.0 - w)) - q.start[2];
            r = ee(q);
        }
        ASSERT_TRUE(r.hit) << "query " << i;
        EXPECT_LE(r.toi, 0.5) << "query " << i;
        EXPECT_NE(r.outcome, CcdOutcome::iteration_cap) << "query " << i;
        most = std::max(most, r.iterations);
    }
    EXPECT_LT(most, CcdParams{}.max_iterations);
}
