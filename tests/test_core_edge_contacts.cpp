// Edge-face contacts (tethash/edge_contacts.hpp): the exact crossing rule on touching cases, equal to the oracle's
// loop over every boundary pair on random deformed scenes, degenerate lattices and with object rules, the same at 1
// and 2 threads; thin slabs crossing with no vertex inside any tet; a strip bent through itself (the self rule).
#include "core_scenes.hpp"
#include "tethash/detect.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/oracle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

using namespace tethash;
using test::Scene;

namespace {

::testing::AssertionResult same(const EdgeFaceResult& got, const EdgeFaceResult& want)
{
    if (got.faces != want.faces || got.edges != want.edges)
        return ::testing::AssertionFailure() << "boundary faces or edges differ";
    const std::size_t n = std::min(got.contacts.size(), want.contacts.size());
    for (std::size_t i = 0; i < n; ++i) {
        const EdgeFaceContact &a = got.contacts[i], &b = want.contacts[i];
        if (a.edge != b.edge || a.face != b.face || a.edge_object != b.edge_object || a.face_object != b.face_object ||
            a.inner_end != b.inner_end || a.edge_t != b.edge_t ||
            std::memcmp(a.face_bary, b.face_bary, sizeof a.face_bary) != 0 ||
            std::memcmp(a.normal, b.normal, sizeof a.normal) != 0 ||
            std::memcmp(a.edge_vertices, b.edge_vertices, sizeof a.edge_vertices) != 0 ||
            std::memcmp(a.face_vertices, b.face_vertices, sizeof a.face_vertices) != 0)
            return ::testing::AssertionFailure() << "contact " << i << ": (edge " << a.edge << ", face " << a.face
                                                 << ") vs oracle (" << b.edge << ", " << b.face << ")";
    }
    if (got.contacts.size() != want.contacts.size())
        return ::testing::AssertionFailure() << got.contacts.size() << " contacts, oracle " << want.contacts.size();
    return ::testing::AssertionSuccess();
}

Eigen::Vector3d row(const Positions& x, Index v)
{
    return x.row(v).transpose();
}

/// The crossing point from the edge and from the triangle agree, the inner end is on the normal's negative side.
void expect_consistent(const Positions& x, const EdgeFaceContact& c)
{
    const Eigen::Vector3d p = row(x, c.edge_vertices[0]), q = row(x, c.edge_vertices[1]);
    const Eigen::Vector3d on_edge = (1 - c.edge_t) * p + c.edge_t * q;
    Eigen::Vector3d on_face = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
        on_face += c.face_bary[k] * row(x, c.face_vertices[k]);
    const double scale = (p - q).norm() + (row(x, c.face_vertices[0]) - row(x, c.face_vertices[1])).norm();
    EXPECT_LT((on_edge - on_face).norm(), 1e-9 * scale);
    EXPECT_GT(c.edge_t, 0.0);
    EXPECT_LT(c.edge_t, 1.0);
    const Eigen::Vector3d n(c.normal[0], c.normal[1], c.normal[2]);
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    const Eigen::Vector3d inner = c.inner_end == 0 ? p : q, outer = c.inner_end == 0 ? q : p;
    EXPECT_LE(n.dot(inner - on_face), 1e-12 * scale);
    EXPECT_GE(n.dot(outer - on_face), -1e-12 * scale);
}

/// Moves every vertex by a smooth random deformation (a bend and a twist) plus jitter of `jitter` × 0.2.
void deform(Scene& s, std::uint32_t seed, double jitter)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double bend = 0.6 * u(rng), twist = 0.8 * u(rng);
    for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
        Eigen::Vector3d p = s.positions.row(v).transpose();
        const double a = twist * p.z();
        p = Eigen::Vector3d(std::cos(a) * p.x() - std::sin(a) * p.y(), std::sin(a) * p.x() + std::cos(a) * p.y(),
                            p.z() + bend * p.x() * p.x());
        p += 0.2 * jitter * Eigen::Vector3d(u(rng), u(rng), u(rng));
        s.positions.row(v) = p.transpose();
    }
}

EdgeFaceResult find(const Scene& s, int threads)
{
    return find_edge_face_contacts(s.tets, s.positions, s.vertex_object, s.tet_object, s.objects, threads);
}
EdgeFaceResult oracle(const Scene& s)
{
    return brute_force_edge_face_contacts(s.tets, s.positions, s.vertex_object, s.tet_object, s.objects);
}

} // namespace

TEST(CoreEdgeContacts, CrossingRuleOnTouchingCases)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
    auto cross = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
        return edge_face_crossing(p.data(), q.data(), a, b, c);
    };
    // Through the interior: t and the barycentric coordinates, the inner end below the (+z) normal.
    EdgeFaceCrossing x = cross({0.2, 0.2, -1}, {0.2, 0.2, 1});
    ASSERT_TRUE(x.crosses);
    EXPECT_DOUBLE_EQ(x.edge_t, 0.5);
    EXPECT_DOUBLE_EQ(x.face_bary[0], 0.6);
    EXPECT_DOUBLE_EQ(x.face_bary[1], 0.2);
    EXPECT_DOUBLE_EQ(x.face_bary[2], 0.2);
    EXPECT_EQ(x.inner_end, 0);
    EXPECT_EQ(cross({0.2, 0.2, 3}, {0.2, 0.2, -1}).inner_end, 1);
    // An end on the plane (inside the triangle or not), an edge in the plane: touching, not crossing.
    EXPECT_FALSE(cross({0.2, 0.2, 0}, {0.2, 0.2, 1}).crosses);
    EXPECT_FALSE(cross({0.2, 0.2, -1}, {0.2, 0.2, 0}).crosses);
    EXPECT_FALSE(cross({-1, 0.2, 0}, {2, 0.2, 0}).crosses);
    // Ends on one side; passing beside the triangle.
    EXPECT_FALSE(cross({0.2, 0.2, 0.5}, {0.2, 0.2, 1}).crosses);
    EXPECT_FALSE(cross({0.6, 0.6, -1}, {0.6, 0.6, 1}).crosses);
    // Through an edge of the triangle (closed): the opposite corner's coordinate is an exact zero.
    x = cross({0.5, 0, -1}, {0.5, 0, 1});
    ASSERT_TRUE(x.crosses);
    EXPECT_EQ(x.face_bary[2], 0.0);
    EXPECT_DOUBLE_EQ(x.face_bary[0], 0.5);
    // Just beside that edge: outside.
    EXPECT_FALSE(cross({0.5, -std::ldexp(1.0, -70), -1}, {0.5, -std::ldexp(1.0, -70), 1}).crosses);
    EXPECT_TRUE(cross({0.5, std::ldexp(1.0, -70), -1}, {0.5, std::ldexp(1.0, -70), 1}).crosses);
    // Through a corner: (1, 0, 0) exactly.
    x = cross({0, 0, -1}, {0, 0, 1});
    ASSERT_TRUE(x.crosses);
    EXPECT_EQ(x.face_bary[0], 1.0);
    EXPECT_EQ(x.face_bary[1], 0.0);
    EXPECT_EQ(x.face_bary[2], 0.0);
    // Through a corner of a triangle in a generic plane (the filter cannot decide the zeros; exact arithmetic does).
    const double ga[3] = {0.1, 0.7, 0.3}, gb[3] = {0.9, 0.2, 0.35}, gc[3] = {0.4, 0.9, 0.65};
    const double p[3] = {0.9, 0.2, -1}, q[3] = {0.9, 0.2, 2};
    x = edge_face_crossing(p, q, ga, gb, gc);
    ASSERT_TRUE(x.crosses);
    EXPECT_EQ(x.face_bary[0], 0.0);
    EXPECT_EQ(x.face_bary[1], 1.0);
    EXPECT_EQ(x.face_bary[2], 0.0);
    // The shared edge of two triangles: once for each.
    const double d[3] = {1, 1, 0};
    const double m0[3] = {0.5, 0.5, -1}, m1[3] = {0.5, 0.5, 1};
    EXPECT_TRUE(edge_face_crossing(m0, m1, a, b, c).crosses);
    EXPECT_TRUE(edge_face_crossing(m0, m1, b, d, c).crosses);
    // A zero-area triangle is never crossed.
    const double e[3] = {2, 0, 0};
    EXPECT_FALSE(edge_face_crossing(m0, m1, a, b, e).crosses);
}

TEST(CoreEdgeContacts, EqualsOracleOnRandomDeformedScenesAtOneAndTwoThreads)
{
    std::int64_t total = 0, self = 0;
    for (std::uint32_t seed = 1; seed <= 8; ++seed) {
        Scene s = test::random_scene(seed, 4, 3, 0.3);
        deform(s, seed, 1.0);
        if (seed > 4) test::set_object_rules(s, seed);
        const EdgeFaceResult want = oracle(s);
        const EdgeFaceResult one = find(s, 1), two = find(s, 2);
        EXPECT_TRUE(same(one, want)) << "seed " << seed;
        EXPECT_TRUE(same(two, want)) << "seed " << seed << ", 2 threads";
        EXPECT_LE(one.candidates, want.candidates);
        EXPECT_EQ(one.candidates, two.candidates);
        for (const EdgeFaceContact& c : want.contacts) {
            expect_consistent(s.positions, c);
            self += c.edge_object == c.face_object;
            if (seed > 4) {
                EXPECT_FALSE(s.objects[c.edge_object].is_static && s.objects[c.face_object].is_static);
                EXPECT_TRUE(c.edge_object != c.face_object || s.objects[c.edge_object].self_collision);
            }
        }
        total += static_cast<std::int64_t>(want.contacts.size());
    }
    EXPECT_GT(total, 100); // the scenes overlap: a test that could fail
    EXPECT_GT(self, 0);    // the jitter folds some tets: far self crossings too
}

TEST(CoreEdgeContacts, DetectorKeptAcrossStepsEqualsOracle)
{
    // One topology, several deformations: the detector's kept boundary, neighbours and rules stay right.
    Scene s = test::random_scene(11, 3, 3, 0.2);
    test::set_object_rules(s, 6);
    EdgeFaceDetector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    std::size_t total = 0;
    for (std::uint32_t step = 1; step <= 4; ++step) {
        deform(s, 100 + step, 0.5);
        const EdgeFaceResult& r = det.find(s.positions, static_cast<int>(step % 2) + 1);
        EXPECT_TRUE(same(r, oracle(s))) << "step " << step;
        total += r.contacts.size();
    }
    EXPECT_GT(total, 0u);
    EXPECT_THROW(det.find(Positions(3, 3)), Error);
}

TEST(CoreEdgeContacts, SkinReusesKeptPairsAndEqualsOracle)
{
    // A scene deformed a little more at every find, carried along by a large common translation: with a skin the
    // finds between full ones test only the kept pairs, and every find equals the oracle and a find without a skin
    // (contacts and candidates), at 1 and 2 threads alternately.
    Scene s = test::random_scene(13, 4, 3, 0.3);
    test::set_object_rules(s, 6);
    const Positions start = s.positions;
    EdgeFaceDetector with, without;
    with.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    without.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    with.set_skin(0.1);
    int reused = 0, full = 0;
    std::size_t total = 0;
    for (int step = 0; step < 24; ++step) {
        // A growing bend (0.01 x² more per step) and 2.5 units of common translation per step.
        s.positions = start;
        const double bend = 0.01 * step;
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
            s.positions(v, 2) += bend * s.positions(v, 0) * s.positions(v, 0);
            s.positions(v, 0) += 2.5 * step;
        }
        const int threads = step % 2 + 1;
        const EdgeFaceResult& got = with.find(s.positions, threads);
        const EdgeFaceResult& plain = without.find(s.positions, 3 - threads);
        EXPECT_TRUE(same(got, oracle(s))) << "step " << step;
        EXPECT_EQ(got.candidates, plain.candidates) << "step " << step;
        EXPECT_EQ(plain.reused, 0);
        EXPECT_EQ(plain.kept_candidates, 0);
        reused += got.reused;
        full += 1 - got.reused;
        if (got.reused == 0) {
            EXPECT_GT(got.kept_candidates, got.candidates) << "the grown boxes keep more pairs";
        }
        total += got.contacts.size();
    }
    EXPECT_GT(reused, 12) << "most finds reuse the kept pairs";
    EXPECT_GT(full, 1) << "the bend outgrows the skin now and then";
    EXPECT_GT(total, 0u);
    EXPECT_THROW(with.set_skin(-1), Error);
    EXPECT_THROW(with.set_skin(std::numeric_limits<double>::infinity()), Error);
}

TEST(CoreEdgeContacts, SkinPausesWhenEverythingMovesAndResumesWhenSlow)
{
    // Every find jitters the scene by far more than the skin: the kept pairs are never reused, so the finds after
    // the second run without them (nothing kept); slow steps then bring the skin back. Always the oracle's contacts.
    Scene s = test::random_scene(17, 3, 3, 0.2);
    EdgeFaceDetector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    det.set_skin(0.01);
    const Positions start = s.positions;
    for (int step = 0; step < 4; ++step) {
        deform(s, 300 + step, 0.5);
        const EdgeFaceResult& r = det.find(s.positions);
        EXPECT_TRUE(same(r, oracle(s))) << "step " << step;
        EXPECT_EQ(r.reused, 0);
        if (step >= 1) {
            EXPECT_EQ(r.kept_candidates, 0) << "paused, step " << step;
        }
    }
    for (int step = 0; step < 3; ++step) {
        s.positions.col(1).array() += 0.001; // slow: 0.001 per find
        s.positions(0, 1) += 0.0001 * step;
        const EdgeFaceResult& r = det.find(s.positions);
        EXPECT_TRUE(same(r, oracle(s))) << "slow step " << step;
        if (step == 0) {
            EXPECT_GT(r.kept_candidates, 0) << "resumed";
        } else {
            EXPECT_EQ(r.reused, 1) << "slow step " << step;
        }
    }
}

TEST(CoreEdgeContacts, LocalReachLeavesOutTheRestLocalSelfPairsOnly)
{
    // With a reach per object, a self pair with a vertex of the edge and one of the triangle nearer than the reach
    // in the rest state is left out; everything else is the oracle's. crosses_locally answers for the pairs left out.
    std::int64_t dropped = 0, kept_self = 0;
    for (std::uint32_t seed = 1; seed <= 6; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 0.3);
        const Positions rest = s.positions;
        deform(s, seed, 1.0);
        const std::vector<double> reach(4, 0.35);
        EdgeFaceDetector det;
        det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
        det.set_local_reach(rest, reach);
        const EdgeFaceResult& got = det.find(s.positions, static_cast<int>(seed % 2) + 1);
        const EdgeFaceResult want = oracle(s);
        EdgeFaceResult filtered = want;
        filtered.contacts.clear();
        std::vector<std::pair<Index, Index>> local; // (edge, object) with a crossing left out
        for (const EdgeFaceContact& c : want.contacts) {
            bool near = false;
            for (const Index a : c.edge_vertices)
                for (const Index b : c.face_vertices)
                    near = near || (rest.row(a) - rest.row(b)).squaredNorm() < 0.35 * 0.35;
            if (c.edge_object == c.face_object && near) {
                local.emplace_back(c.edge, c.face_object);
                ++dropped;
            } else {
                filtered.contacts.push_back(c);
                kept_self += c.edge_object == c.face_object;
            }
        }
        EXPECT_TRUE(same(got, filtered)) << "seed " << seed;
        std::sort(local.begin(), local.end());
        for (Index e = 0; e < want.edges.rows(); ++e) {
            const Index object =
                s.vertex_object.empty() ? 0 : s.vertex_object[static_cast<std::size_t>(want.edges(e, 0))];
            const bool expect = std::binary_search(local.begin(), local.end(), std::make_pair(e, object));
            EXPECT_EQ(det.crosses_locally(e, object, s.positions), expect) << "seed " << seed << ", edge " << e;
            EXPECT_FALSE(det.crosses_locally(e, object + 1, s.positions));
        }
    }
    EXPECT_GT(dropped, 0);   // the rule left something out
    EXPECT_GT(kept_self, 0); // and kept far self crossings
    EdgeFaceDetector det;
    Scene s = test::random_scene(1, 2, 2, 0.1);
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    const std::vector<double> bad = {-1.0, 1.0};
    EXPECT_THROW(det.set_local_reach(s.positions, bad), Error);
    EXPECT_THROW(det.set_local_reach(Positions(2, 3), std::vector<double>(2, 1.0)), Error);
}

TEST(CoreEdgeContacts, EqualsOracleOnDegenerateLattices)
{
    // Lattices shifted by half a cube or along a face: ends on planes, lines through edges and corners.
    const Eigen::Vector3d shifts[] = {{0.25, 0.25, 0.25}, {0.5, 0.25, 0}, {0.25, 0, 0}, {0.5, 0.5, 0.5}};
    std::int64_t total = 0;
    for (const Eigen::Vector3d& shift : shifts) {
        Scene s = test::lattice_pair(2, 0.5, shift, Eigen::Vector3d::Zero());
        const EdgeFaceResult want = oracle(s);
        EXPECT_TRUE(same(find(s, 1), want)) << shift.transpose();
        EXPECT_TRUE(same(find(s, 2), want)) << shift.transpose();
        total += static_cast<std::int64_t>(want.contacts.size());
        test::make_coincident(s, 7);
        EXPECT_TRUE(same(find(s, 2), oracle(s))) << shift.transpose() << " coincident";
    }
    EXPECT_GT(total, 0);
}

TEST(CoreEdgeContacts, EqualsOracleWithTrianglesOfVerySizes)
{
    // A 10 × 10 slab of 6 tets (huge triangles) pierced by a bundle of 0.1 cubes: the grid's cell (the mean edge)
    // would put each big triangle in 10^4 cells, so it is coarsened; nothing may be missed.
    Scene s = test::lattice_object(1, 1, 1, 10.0, Eigen::Vector3d(-5, -5, 0));
    for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
        s.positions(v, 2) *= 0.01;
    Scene b = test::lattice_object(2, 2, 8, 0.1, Eigen::Vector3d(0.013, 0.021, -0.37));
    deform(b, 5, 0.1);
    test::append_object(s, b);
    const EdgeFaceResult want = oracle(s);
    EXPECT_TRUE(same(find(s, 1), want));
    EXPECT_TRUE(same(find(s, 2), want));
    EXPECT_GT(want.contacts.size(), 8u);
}

TEST(CoreEdgeContacts, ThinSlabsCrossWithNoVertexInsideAnyTet)
{
    // A: 4 × 4 cubes in x, y, 0.02 thick in z. B: the same slab stood up (its thin side in y), passing through A's
    // middle between lattice lines; no vertex of either is inside the other.
    const double h = 0.25;
    Scene s = test::lattice_object(4, 4, 1, h, Eigen::Vector3d::Zero());
    for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
        s.positions(v, 2) *= 0.08;
    Scene b = test::lattice_object(4, 1, 4, h, Eigen::Vector3d::Zero());
    for (Eigen::Index v = 0; v < b.positions.rows(); ++v) {
        b.positions(v, 0) += 0.1;
        b.positions(v, 1) = 0.43 + 0.08 * b.positions(v, 1);
        b.positions(v, 2) -= 0.55;
    }
    test::append_object(s, b);
    EXPECT_TRUE(brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object).empty());
    Detector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    EXPECT_TRUE(det.detect(s.positions).empty());

    const EdgeFaceResult r = find(s, 2);
    EXPECT_TRUE(same(r, oracle(s)));
    int a_through_b = 0, b_through_a = 0;
    for (const EdgeFaceContact& c : r.contacts) {
        EXPECT_NE(c.edge_object, c.face_object);
        expect_consistent(s.positions, c);
        (c.edge_object == 0 ? a_through_b : b_through_a) += 1;
    }
    EXPECT_GT(a_through_b, 0); // A's edges along y cross B's two large faces
    EXPECT_GT(b_through_a, 0); // B's edges along z cross A's top and bottom
    // Every edge of B from below A to above it, starting over A (x < 1), crosses A's bottom and A's top once each.
    int b_edges_through = 0;
    for (Index e = 0; e < r.edges.rows(); ++e) {
        const double z0 = s.positions(r.edges(e, 0), 2), z1 = s.positions(r.edges(e, 1), 2);
        const double y0 = s.positions(r.edges(e, 0), 1), x0 = s.positions(r.edges(e, 0), 0),
                     x1 = s.positions(r.edges(e, 1), 0);
        if (y0 > 0.4 && std::min(x0, x1) < 1 && std::min(z0, z1) < 0 && std::max(z0, z1) > 0.02) ++b_edges_through;
    }
    EXPECT_EQ(b_through_a, 2 * b_edges_through);

    // Rules: B static and A static: nothing; self-collision off changes nothing (no self crossing).
    s.objects.resize(2);
    s.objects[0].is_static = s.objects[1].is_static = true;
    EXPECT_TRUE(find(s, 1).contacts.empty());
    s.objects[0].is_static = false;
    s.objects[0].self_collision = s.objects[1].self_collision = false;
    EXPECT_EQ(find(s, 1).contacts.size(), r.contacts.size());
}

TEST(CoreEdgeContacts, StripBentThroughItselfFollowsTheSelfRule)
{
    // A strip of 48 × 1 × 1 cells along the nodal cubic x = u² − 1, z = u (u² − 1), u in [−1.6, 1.6], which
    // crosses itself at u = ±1 (at 90°): far parts of one object pass through each other.
    const int n = 48;
    Scene s = test::lattice_object(n, 1, 1, 1.0, Eigen::Vector3d::Zero());
    const Scene straight = s;
    for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
        const double u = -1.6 + 3.2 * s.positions(v, 0) / n;
        const Eigen::Vector2d c(u * u - 1, u * (u * u - 1)), t = Eigen::Vector2d(2 * u, 3 * u * u - 1).normalized();
        const Eigen::Vector2d normal(-t.y(), t.x());
        const Eigen::Vector2d xz = c + (s.positions(v, 2) - 0.5) * 0.04 * normal;
        s.positions.row(v) << xz.x(), 0.3 * s.positions(v, 1), xz.y();
    }
    const EdgeFaceResult r = find(s, 2);
    EXPECT_TRUE(same(r, oracle(s)));
    ASSERT_FALSE(r.contacts.empty());
    // Every contact is between the two passes (u near −1 and u near 1), far apart along the strip.
    auto cell = [&](Index v) { return v % (n + 1); };
    for (const EdgeFaceContact& c : r.contacts) {
        expect_consistent(s.positions, c);
        const int gap = std::abs(cell(c.edge_vertices[0]) - cell(c.face_vertices[0]));
        EXPECT_GT(gap, n / 3) << "edge " << c.edge << ", face " << c.face;
    }
    // Unbent, the strip has no contact: neighbours never count.
    EXPECT_TRUE(find(straight, 1).contacts.empty());
    // Self-collision off: none.
    s.objects.resize(1);
    s.objects[0].self_collision = false;
    EXPECT_TRUE(find(s, 1).contacts.empty());
    EXPECT_TRUE(oracle(s).contacts.empty());
}

TEST(CoreEdgeContacts, NeighboursWithinOneTetNeverCount)
{
    // Two tets sharing a vertex, the second pushed through the first: their edges cross faces, but each edge and
    // face share a vertex or a tet, so as one object nothing is reported; as two objects (no shared vertex: apart)
    // the crossings are.
    Positions x(8, 3);
    x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1,                           // tet 0
        0.2, 0.2, -0.5, 0.3, 0.2, 0.6, 0.2, 0.3, 0.6, 0.25, 0.25, 1.5; // tet 1: a spike through tet 0's base
    Tets tets(2, 4);
    tets << 0, 1, 2, 3, 4, 5, 6, 7;
    if (signed_volume(x, {4, 5, 6, 7}) < 0) std::swap(tets(1, 2), tets(1, 3));
    const std::vector<Index> two_objects = {0, 0, 0, 0, 1, 1, 1, 1}, tet_two = {0, 1};
    const EdgeFaceResult apart = find_edge_face_contacts(tets, x, two_objects, tet_two);
    EXPECT_FALSE(apart.contacts.empty());
    EXPECT_TRUE(same(apart, brute_force_edge_face_contacts(tets, x, two_objects, tet_two)));
    // One object with a bridging tet joining vertex 0 and 4 (and 1, 5): every crossing pair is now one tet apart.
    Tets joined(3, 4);
    joined << tets, 0, 1, 4, 5;
    const EdgeFaceResult one = find_edge_face_contacts(joined, x);
    const EdgeFaceResult ref = brute_force_edge_face_contacts(joined, x);
    EXPECT_TRUE(same(one, ref));
    for (const EdgeFaceContact& c : one.contacts)
        for (const Index u : c.edge_vertices)
            for (const Index w : c.face_vertices) {
                EXPECT_NE(u, w);
                bool share = false;
                for (Eigen::Index t = 0; t < joined.rows(); ++t)
                    share = share || ((joined.row(t).array() == u).any() && (joined.row(t).array() == w).any());
                EXPECT_FALSE(share) << "edge " << c.edge << ", face " << c.face;
            }
}

TEST(CoreEdgeContacts, RefusesBadInput)
{
    Scene s = test::lattice_object(1, 1, 1, 1.0, Eigen::Vector3d::Zero());
    Positions bad = s.positions;
    bad(2, 1) = std::nan("");
    EXPECT_THROW(find_edge_face_contacts(s.tets, bad), Error);
    Tets out = s.tets;
    out(0, 0) = 99;
    EXPECT_THROW(find_edge_face_contacts(out, s.positions), Error);
    EXPECT_THROW(brute_force_edge_face_contacts(out, s.positions), Error);
    EXPECT_THROW(find_edge_face_contacts(s.tets, s.positions, {}, {}, {}, -1), Error);
    const std::vector<Index> short_objects = {0, 0};
    EXPECT_THROW(find_edge_face_contacts(s.tets, s.positions, short_objects), Error);
    EXPECT_TRUE(find_edge_face_contacts(Tets(0, 4), Positions(0, 3)).contacts.empty());
}
