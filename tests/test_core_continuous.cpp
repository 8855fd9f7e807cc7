// Continuous detection on meshes (tethash/continuous.hpp): equal to the brute-force loop over all boundary pairs
// (the same narrow phase) on moving lattice blocks, the same at 1 and 2 threads, and it sees what discrete
// detection cannot: a body passing through another within a step, edges crossing with no vertex inside.
#include "support.hpp"
#include "tethash/continuous.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace tethash;
using namespace tethash::ccd;

namespace {

/// A lattice block of n × n × n cubes, 6 tets each, corner at `origin`, cube edge `h`, appended to (x, tets).
void add_block(std::vector<Eigen::Vector3d>& x, std::vector<std::array<Index, 4>>& tets, int n, double h,
               const Eigen::Vector3d& origin)
{
    const Index base = static_cast<Index>(x.size());
    for (int k = 0; k <= n; ++k)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i)
                x.push_back(origin + h * Eigen::Vector3d(i, j, k));
    const auto id = [&](int i, int j, int k) { return base + static_cast<Index>(i + (n + 1) * (j + (n + 1) * k)); };
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                for (const auto& t : test::kuhn_tets(i, j, k, id))
                    tets.push_back(t);
}

struct Scene {
    Tets tets;
    Positions x0, x1;
};

/// Block A still at the origin; block B starting at `start` and moving by `move`; every vertex jittered by up to
/// `jitter` at both ends (seeded).
Scene two_blocks(const Eigen::Vector3d& start, const Eigen::Vector3d& move, double jitter, unsigned seed)
{
    std::vector<Eigen::Vector3d> x;
    std::vector<std::array<Index, 4>> tets;
    add_block(x, tets, 2, 0.5, Eigen::Vector3d::Zero());
    const std::size_t first_b = x.size();
    add_block(x, tets, 2, 0.5, start);
    Scene s;
    s.tets = test::matrix_of<Tets>(tets);
    s.x0 = test::matrix_of<Positions>(x);
    s.x1 = s.x0;
    for (std::size_t i = first_b; i < x.size(); ++i)
        s.x1.row(static_cast<Eigen::Index>(i)) += move.transpose();
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> d(-jitter, jitter);
    for (Positions* p : {&s.x0, &s.x1})
        for (Eigen::Index i = 0; i < p->rows(); ++i)
            for (int k = 0; k < 3; ++k)
                (*p)(i, k) += d(rng);
    return s;
}

void expect_same(const ContinuousResult& a, const ContinuousResult& b, const std::string& what)
{
    ASSERT_EQ(a.contacts.size(), b.contacts.size()) << what;
    for (std::size_t i = 0; i < a.contacts.size(); ++i) {
        EXPECT_EQ(a.contacts[i].kind, b.contacts[i].kind) << what << " contact " << i;
        EXPECT_EQ(a.contacts[i].a, b.contacts[i].a) << what << " contact " << i;
        EXPECT_EQ(a.contacts[i].b, b.contacts[i].b) << what << " contact " << i;
        EXPECT_EQ(a.contacts[i].toi, b.contacts[i].toi) << what << " contact " << i;
    }
}

} // namespace

TEST(CoreContinuous, EqualsBruteForceAndThreadCounts)
{
    int with_contacts = 0;
    for (unsigned seed = 1; seed <= 6; ++seed) {
        // B sweeps through A's corner region, from far to overlapping or past, with jitter.
        const Scene s = two_blocks({1.6, 0.3, 0.2}, {-1.2 - 0.2 * seed, 0.1 * seed, -0.05 * seed}, 0.05, seed);
        const ContinuousResult brute = detect_continuous_brute_force(s.tets, s.x0, s.x1);
        ContinuousParams one, two;
        one.threads = 1;
        two.threads = 2;
        const ContinuousResult r1 = detect_continuous(s.tets, s.x0, s.x1, one);
        const ContinuousResult r2 = detect_continuous(s.tets, s.x0, s.x1, two);
        expect_same(r1, brute, "seed " + std::to_string(seed) + ", 1 thread vs brute force");
        expect_same(r2, r1, "seed " + std::to_string(seed) + ", 2 threads vs 1");
        EXPECT_LT(r1.vertex_face_candidates, brute.vertex_face_candidates / 4) << "the broad phase prunes";
        with_contacts += !r1.contacts.empty();
        // Both kinds, and the self-contacts of a jittered block are none (its parts do not move into each other).
        bool vf = false, ee = false;
        for (const auto& c : r1.contacts) {
            vf = vf || c.kind == ContinuousKind::vertex_face;
            ee = ee || c.kind == ContinuousKind::edge_edge;
            EXPECT_GE(c.toi, 0.0);
            EXPECT_LE(c.toi, 1.0);
        }
        EXPECT_TRUE(vf && ee) << "seed " << seed;
    }
    EXPECT_EQ(with_contacts, 6);
}

TEST(CoreContinuous, SeesABodyPassingThroughWithinTheStep)
{
    // B starts left of A and ends right of it, overlapping it at neither end: discrete detection at the frames
    // sees nothing, the step's sweep meets A.
    const Scene s = two_blocks({-2, 0.25, 0.25}, {4, 0, 0}, 0.0, 1);
    const ContinuousResult r = detect_continuous(s.tets, s.x0, s.x1);
    ASSERT_FALSE(r.contacts.empty());
    double first = 1;
    for (const auto& c : r.contacts)
        first = std::min(first, c.toi);
    // B's right face (x = -1 at t = 0, moving 4 per unit t) reaches A's left face (x = 0) at t = 0.25.
    EXPECT_LE(first, 0.25);
    EXPECT_GE(first, 0.25 - 1e-5);
}

TEST(CoreContinuous, EdgesCrossingWithNoVertexInside)
{
    // Two tets whose edges cross through each other's faces at the end of the step, no vertex in the other tet:
    // a tet lying along x (its edge (0,0,0)-(2,0,0)) and a thin tet across it, moving down onto it.
    const Tets tets = test::matrix_of<Tets>(std::vector<std::array<Index, 4>>{{0, 1, 2, 3}, {4, 5, 6, 7}});
    const Positions x0 = test::matrix_of<Positions>(std::vector<Eigen::Vector3d>{
        {0, 0, 0}, {2, 0, 0}, {1, -0.1, -1}, {1, 0.1, -1}, {1, -1, 1}, {1, 1, 1}, {0.9, 0, 2}, {1.1, 0, 2}});
    Positions x1 = x0;
    for (int v = 4; v < 8; ++v)
        x1(v, 2) -= 1.5; // the lower edge of tet 1 ends at z = -0.5, below edge (0,0,0)-(2,0,0)
    const ContinuousResult r = detect_continuous(tets, x0, x1);
    bool edge_edge = false;
    for (const auto& c : r.contacts)
        edge_edge = edge_edge || c.kind == ContinuousKind::edge_edge;
    EXPECT_TRUE(edge_edge);
    expect_same(r, detect_continuous_brute_force(tets, x0, x1), "crossing tets");
}

TEST(CoreContinuous, BadInputIsAnError)
{
    const Tets tets = test::matrix_of<Tets>(std::vector<std::array<Index, 4>>{{0, 1, 2, 4}});
    const Positions x = Positions::Zero(4, 3);
    test::expect_error([&] { detect_continuous(tets, x, x); }, {"tet 0", "vertex 4"});
    test::expect_error([&] { detect_continuous(tets, x, Positions::Zero(5, 3)); }, {"4 rows", "5"});
    Positions bad = Positions::Zero(5, 3);
    bad(3, 1) = std::numeric_limits<double>::infinity();
    test::expect_error([&] { detect_continuous(tets, Positions::Zero(5, 3), bad); }, {"vertex 3", "end"});
}

TEST(CoreContinuous, CandidatesAreTheOverlappingPairsTheNarrowPhaseGets)
{
    const Scene s = two_blocks({1.6, 0.3, 0.2}, {-1.5, 0.2, -0.1}, 0.05, 3);
    const ContinuousCandidates c1 = continuous_candidates(s.tets, s.x0, s.x1, 1);
    const ContinuousCandidates c2 = continuous_candidates(s.tets, s.x0, s.x1, 2);
    EXPECT_EQ(c1.vertex_face, c2.vertex_face);
    EXPECT_EQ(c1.edge_edge, c2.edge_edge);
    // The reference: every pair by a loop, swept boxes of the corners at both ends, pairs sharing a vertex left out.
    const auto box = [&](std::vector<Index> ids) {
        Eigen::Array3d lo = s.x0.row(ids[0]).transpose().array(), hi = lo;
        for (const Index v : ids)
            for (const Positions* x : {&s.x0, &s.x1}) {
                lo = lo.min(x->row(v).transpose().array());
                hi = hi.max(x->row(v).transpose().array());
            }
        return std::make_pair(lo, hi);
    };
    const auto overlap = [](const auto& a, const auto& b) {
        return !((a.first > b.second).any() || (b.first > a.second).any());
    };
    std::vector<Index> vertices(c1.faces.data(), c1.faces.data() + c1.faces.size());
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    std::vector<std::array<Index, 2>> vf, ee;
    for (const Index v : vertices)
        for (Index f = 0; f < c1.faces.rows(); ++f) {
            const std::vector<Index> face{c1.faces(f, 0), c1.faces(f, 1), c1.faces(f, 2)};
            if (std::find(face.begin(), face.end(), v) == face.end() && overlap(box({v}), box(face)))
                vf.push_back({v, f});
        }
    for (Index e = 0; e < c1.edges.rows(); ++e)
        for (Index g = e + 1; g < c1.edges.rows(); ++g) {
            const Index a0 = c1.edges(e, 0), a1 = c1.edges(e, 1), b0 = c1.edges(g, 0), b1 = c1.edges(g, 1);
            if (a0 != b0 && a0 != b1 && a1 != b0 && a1 != b1 && overlap(box({a0, a1}), box({b0, b1})))
                ee.push_back({e, g});
        }
    EXPECT_EQ(c1.vertex_face, vf);
    EXPECT_EQ(c1.edge_edge, ee);
    ASSERT_GT(vf.size(), 10u);
    ASSERT_GT(ee.size(), 10u);
    // As many as continuous detection counts, and every contact of it among them.
    const ContinuousResult r = detect_continuous(s.tets, s.x0, s.x1);
    EXPECT_EQ(r.vertex_face_candidates, static_cast<std::int64_t>(vf.size()));
    EXPECT_EQ(r.edge_edge_candidates, static_cast<std::int64_t>(ee.size()));
    const ContinuousResult brute = detect_continuous_brute_force(s.tets, s.x0, s.x1);
    EXPECT_GT(brute.vertex_face_candidates, r.vertex_face_candidates);
    ASSERT_FALSE(r.contacts.empty());
    for (const ContinuousContact& c : r.contacts) {
        const auto& list = c.kind == ContinuousKind::vertex_face ? vf : ee;
        EXPECT_TRUE(std::binary_search(list.begin(), list.end(), std::array<Index, 2>{c.a, c.b}));
    }
    // Brute force counts every pair that shares no vertex.
    std::int64_t sharing_free = 0;
    for (const Index v : vertices)
        for (Index f = 0; f < c1.faces.rows(); ++f)
            sharing_free += c1.faces(f, 0) != v && c1.faces(f, 1) != v && c1.faces(f, 2) != v;
    EXPECT_EQ(brute.vertex_face_candidates, sharing_free);
}

TEST(CoreContinuous, KeptDetectorEqualsDetectContinuousAtOneAndTwoThreads)
{
    // One detector kept over steps of the same tets: each step's contacts, tois and candidate counts are
    // detect_continuous's (itself checked against brute force above), at 1 and 2 threads.
    ContinuousDetector one, two;
    int with_contacts = 0;
    for (unsigned seed = 1; seed <= 6; ++seed) {
        const Scene s = two_blocks({1.6, 0.3, 0.2}, {-1.2 - 0.2 * seed, 0.1 * seed, -0.05 * seed}, 0.05, seed);
        if (seed == 1) {
            one.set_topology(s.tets, static_cast<Index>(s.x0.rows()));
            two.set_topology(s.tets, static_cast<Index>(s.x0.rows()));
        }
        ContinuousParams p1, p2;
        p1.threads = 1;
        p2.threads = 2;
        const ContinuousResult want = detect_continuous(s.tets, s.x0, s.x1, p1);
        const ContinuousResult& r1 = one.detect(s.x0, s.x1, p1);
        expect_same(r1, want, "seed " + std::to_string(seed) + ", kept at 1 thread");
        EXPECT_EQ(r1.vertex_face_candidates, want.vertex_face_candidates);
        EXPECT_EQ(r1.edge_edge_candidates, want.edge_edge_candidates);
        EXPECT_TRUE(r1.faces == want.faces && r1.edges == want.edges);
        const ContinuousResult& r2 = two.detect(s.x0, s.x1, p2);
        expect_same(r2, want, "seed " + std::to_string(seed) + ", kept at 2 threads");
        EXPECT_EQ(r2.vertex_face_candidates, want.vertex_face_candidates);
        EXPECT_EQ(r2.edge_edge_candidates, want.edge_edge_candidates);
        with_contacts += !want.contacts.empty();
    }
    EXPECT_EQ(with_contacts, 6);
}

TEST(CoreContinuous, KeptDetectorMovingMaskAndFilter)
{
    // Only block B's vertices marked moving: the contacts are exactly those of the full detection that involve a
    // vertex of B (A's own pairs, which its jitter moves, are not candidates), at 1 and 2 threads; a filter that
    // refuses vertex-face pairs leaves the edge-edge contacts alone.
    const Scene s = two_blocks({1.6, 0.3, 0.2}, {-1.5, 0.2, -0.1}, 0.05, 3);
    const auto n = static_cast<Index>(s.x0.rows());
    std::vector<unsigned char> moving(static_cast<std::size_t>(n), 0);
    for (Index v = n / 2; v < n; ++v) // the blocks have as many vertices each, B second
        moving[static_cast<std::size_t>(v)] = 1;
    ContinuousDetector d;
    d.set_topology(s.tets, n);
    const ContinuousResult all = d.detect(s.x0, s.x1);
    const auto involves_b = [&](const ContinuousContact& c) {
        if (c.kind == ContinuousKind::vertex_face)
            return moving[static_cast<std::size_t>(c.a)] || moving[static_cast<std::size_t>(all.faces(c.b, 0))];
        return moving[static_cast<std::size_t>(all.edges(c.a, 0))] ||
               moving[static_cast<std::size_t>(all.edges(c.b, 0))];
    };
    ContinuousResult want = all;
    want.contacts.clear();
    for (const auto& c : all.contacts)
        if (involves_b(c)) want.contacts.push_back(c);
    ASSERT_FALSE(want.contacts.empty());
    for (int threads : {1, 2}) {
        ContinuousParams p;
        p.threads = threads;
        const ContinuousResult& masked = d.detect(s.x0, s.x1, p, moving);
        expect_same(masked, want, "masked at " + std::to_string(threads) + " threads");
        EXPECT_LT(masked.vertex_face_candidates, all.vertex_face_candidates);
    }
    ContinuousResult edges_only = all;
    edges_only.contacts.clear();
    for (const auto& c : all.contacts)
        if (c.kind == ContinuousKind::edge_edge) edges_only.contacts.push_back(c);
    ASSERT_FALSE(edges_only.contacts.empty());
    const ContinuousResult& filtered =
        d.detect(s.x0, s.x1, {}, {}, [](ContinuousKind k, Index, Index) { return k == ContinuousKind::edge_edge; });
    expect_same(filtered, edges_only, "edge-edge only");
    EXPECT_EQ(filtered.vertex_face_candidates, 0);
    EXPECT_EQ(filtered.edge_edge_candidates, all.edge_edge_candidates);
    // First only: at least one contact, each one of the full detection's, at 1 and 2 threads; none where nothing
    // meets (B far from A).
    for (int threads : {1, 2}) {
        ContinuousParams p;
        p.threads = threads;
        p.first_only = true;
        const ContinuousResult& first = d.detect(s.x0, s.x1, p);
        ASSERT_FALSE(first.contacts.empty()) << threads;
        EXPECT_LT(first.contacts.size(), all.contacts.size()) << threads;
        for (const auto& c : first.contacts)
            EXPECT_TRUE(std::any_of(all.contacts.begin(), all.contacts.end(), [&](const ContinuousContact& q) {
                return q.kind == c.kind && q.a == c.a && q.b == c.b && q.toi == c.toi;
            }));
        Positions far0 = s.x0, far1 = s.x1;
        for (Index v = n / 2; v < n; ++v) {
            far0(v, 0) += 10;
            far1(v, 0) += 10;
        }
        EXPECT_TRUE(d.detect(far0, far1, p).contacts.empty()) << threads;
    }
    // Positions of another size are refused.
    test::expect_error([&] { d.detect(s.x0.topRows(n - 1), s.x1); }, {"start", "rows"});
}

TEST(CoreContinuous, KeptDetectorMeetsEachPairOnce)
{
    // The broad phase's work: the pairs its grid meets are at most the pairs whose boxes (grown by the grid's
    // single-precision rounding) meet, each once (a moving edge does not meet the other half of a moving pair, nor
    // itself), and at least the candidates; without a mask and with one (pairs with a moving primitive only).
    const Scene s = two_blocks({1.6, 0.3, 0.2}, {-1.5, 0.2, -0.1}, 0.05, 3);
    const auto n = static_cast<Index>(s.x0.rows());
    ContinuousDetector d;
    d.set_topology(s.tets, n);
    const Triangles& faces = d.faces();
    const Edges& edges = d.edges();
    using Box = std::pair<Eigen::Array3d, Eigen::Array3d>;
    const auto box = [&](std::initializer_list<Index> ids) {
        Box b{Eigen::Array3d::Constant(INFINITY), Eigen::Array3d::Constant(-INFINITY)};
        for (const Index v : ids)
            for (const Positions* x : {&s.x0, &s.x1}) {
                b.first = b.first.min(x->row(v).transpose().array());
                b.second = b.second.max(x->row(v).transpose().array());
            }
        const Eigen::Array3d grow = 1e-6 * b.first.abs().max(b.second.abs()) + 1e-29;
        return Box{b.first - grow, b.second + grow};
    };
    const auto meet = [](const Box& a, const Box& b) {
        return !((a.first > b.second).any() || (b.first > a.second).any());
    };
    std::vector<Index> vertices(faces.data(), faces.data() + faces.size());
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    for (const bool masked : {false, true}) {
        std::vector<unsigned char> moving(static_cast<std::size_t>(n), 1);
        if (masked)
            for (Index v = 0; v < n / 2; ++v) // block A still
                moving[static_cast<std::size_t>(v)] = 0;
        const auto mv = [&](Index v) { return moving[static_cast<std::size_t>(v)] != 0; };
        std::int64_t bound = 0;
        for (const Index v : vertices)
            for (Index f = 0; f < faces.rows(); ++f)
                bound += (mv(v) || mv(faces(f, 0)) || mv(faces(f, 1)) || mv(faces(f, 2))) &&
                         meet(box({v}), box({faces(f, 0), faces(f, 1), faces(f, 2)}));
        for (Index e = 0; e < edges.rows(); ++e)
            for (Index g = e + 1; g < edges.rows(); ++g)
                bound += (mv(edges(e, 0)) || mv(edges(e, 1)) || mv(edges(g, 0)) || mv(edges(g, 1))) &&
                         meet(box({edges(e, 0), edges(e, 1)}), box({edges(g, 0), edges(g, 1)}));
        for (int threads : {1, 2}) {
            ContinuousParams p;
            p.threads = threads;
            const ContinuousResult& r = masked ? d.detect(s.x0, s.x1, p, moving) : d.detect(s.x0, s.x1, p);
            const std::string what = (masked ? "masked, " : "") + std::to_string(threads) + " threads";
            EXPECT_LE(r.broad_phase_pairs, bound) << what;
            EXPECT_GE(r.broad_phase_pairs, r.vertex_face_candidates + r.edge_edge_candidates) << what;
            EXPECT_GT(r.edge_edge_candidates, 100) << what;
        }
    }
}

TEST(CoreContinuous, KeptDetectorLocalityRule)
{
    // set_locality leaves out, in the broad phase, the pairs a filter refusing local pairs (the same rule written
    // plainly) refuses before the narrow phase: the same contacts, tois and candidate counts, at 1 and 2 threads,
    // with and without a mask; the rule leaves pairs out (fewer candidates than without it) and contacts remain.
    // Each block is its own group; block B's reach is 1.2 cube edges at rest (its neighbours), block A's 0.
    const Scene s = two_blocks({1.6, 0.3, 0.2}, {-1.5, 0.2, -0.1}, 0.05, 3);
    const auto n = static_cast<Index>(s.x0.rows());
    std::vector<Index> group(static_cast<std::size_t>(n), 0);
    for (Index v = n / 2; v < n; ++v)
        group[static_cast<std::size_t>(v)] = 1;
    const std::vector<double> reach_sq{0.0, 0.36};
    const Positions rest = s.x0;
    ContinuousDetector plain, ruled;
    plain.set_topology(s.tets, n);
    ruled.set_topology(s.tets, n);
    ruled.set_locality(rest, group, reach_sq);
    const Triangles& faces = plain.faces();
    const Edges& edges = plain.edges();
    const auto local = [&](std::vector<Index> a, std::vector<Index> b) {
        const Index g = group[static_cast<std::size_t>(a[0])];
        if (g != group[static_cast<std::size_t>(b[0])]) return false;
        for (const Index u : a)
            for (const Index w : b)
                if ((rest.row(u) - rest.row(w)).squaredNorm() < reach_sq[static_cast<std::size_t>(g)]) return true;
        return false;
    };
    const ContinuousDetector::PairFilter far = [&](ContinuousKind kind, Index a, Index b) {
        if (kind == ContinuousKind::vertex_face) return !local({a}, {faces(b, 0), faces(b, 1), faces(b, 2)});
        return !local({edges(a, 0), edges(a, 1)}, {edges(b, 0), edges(b, 1)});
    };
    std::vector<unsigned char> moving(static_cast<std::size_t>(n), 0);
    for (Index v = n / 2; v < n; ++v)
        moving[static_cast<std::size_t>(v)] = 1;
    const ContinuousResult unruled = plain.detect(s.x0, s.x1);
    for (const bool masked : {false, true})
        for (int threads : {1, 2}) {
            ContinuousParams p;
            p.threads = threads;
            const std::span<const unsigned char> mask =
                masked ? std::span<const unsigned char>(moving) : std::span<const unsigned char>();
            const ContinuousResult want = plain.detect(s.x0, s.x1, p, mask, far);
            const ContinuousResult& got = ruled.detect(s.x0, s.x1, p, mask);
            const std::string what = (masked ? "masked, " : "") + std::to_string(threads) + " threads";
            expect_same(got, want, what);
            EXPECT_EQ(got.vertex_face_candidates, want.vertex_face_candidates) << what;
            EXPECT_EQ(got.edge_edge_candidates, want.edge_edge_candidates) << what;
            EXPECT_LT(got.vertex_face_candidates + got.edge_edge_candidates,
                      unruled.vertex_face_candidates + unruled.edge_edge_candidates)
                << what;
            EXPECT_FALSE(got.contacts.empty()) << what;
        }
    // Bad input names what and where.
    test::expect_error([&] { ruled.set_locality(rest.topRows(n - 1), group, reach_sq); }, {"rest positions", "rows"});
    std::vector<Index> bad_group = group;
    bad_group[5] = 2;
    test::expect_error([&] { ruled.set_locality(rest, bad_group, reach_sq); }, {"vertex 5", "group 2"});
    test::expect_error([&] { ruled.set_locality(rest, group, std::vector<double>{0.0, -1.0}); }, {"group 1"});
    Positions bad_rest = rest;
    bad_rest(7, 2) = NAN;
    test::expect_error([&] { ruled.set_locality(bad_rest, group, reach_sq); }, {"vertex 7", "coordinate 2"});
}
