// Consistent penetration depth (Heidelberger et al. 2004): exact on planar boundaries, propagation,
// the closest-point fallback, the exact-distance reference, bad input, and the state kept between calls
// (refitted or rebuilt trees, reused scratch) changing nothing: bit for bit what a fresh Penetration gives.
#include "core_scenes.hpp"
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/penetration.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>

// Counts heap allocations while g_count_allocations is set (this test binary only). Not inlined: GCC would
// otherwise pair the inlined free() with the operator new of the standard library and warn.
namespace {
std::atomic<bool> g_count_allocations{false};
std::atomic<long> g_allocations{0};
} // namespace

[[gnu::noinline]] void* operator new(std::size_t n)
{
    if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept
{
    std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept
{
    std::free(p);
}

using namespace tethash;

namespace {

/// Cube of edge `size` centred at `at`, `res` lattice cubes per side (6 tets each), as one object.
TetMesh box(int res, double size, const Eigen::Vector3d& at)
{
    const test::Scene s = test::lattice_object(res, res, res, size / res, at - Eigen::Vector3d::Constant(0.5 * size));
    TetMesh m;
    m.positions = s.positions;
    m.tets = s.tets;
    return m;
}

/// Brute force: every vertex of one object inside (closed) a tet of another object.
std::vector<Contact> brute_contacts(const TetMesh& m)
{
    std::vector<Contact> out;
    for (Index v = 0; v < m.num_vertices(); ++v)
        for (Index t = 0; t < m.num_tets(); ++t) {
            if (m.vertex_object[static_cast<size_t>(v)] == m.tet_object[static_cast<size_t>(t)]) continue;
            Eigen::Matrix3d A;
            const Eigen::Vector3d a = m.positions.row(m.tets(t, 0)).transpose();
            for (int k = 0; k < 3; ++k)
                A.col(k) = m.positions.row(m.tets(t, k + 1)).transpose() - a;
            const Eigen::Vector3d l = A.lu().solve(m.positions.row(v).transpose() - a);
            const double b[4] = {1 - l.sum(), l[0], l[1], l[2]};
            if (*std::min_element(b, b + 4) < -1e-12) continue;
            Contact c;
            c.vertex = v;
            c.tet = t;
            c.vertex_object = m.vertex_object[static_cast<size_t>(v)];
            c.tet_object = m.tet_object[static_cast<size_t>(t)];
            std::copy(b, b + 4, c.bary);
            out.push_back(c);
        }
    return out;
}

/// Same bits (not only equal values: -0 and 0 differ).
bool same_bits(double a, double b)
{
    return std::memcmp(&a, &b, sizeof a) == 0;
}

/// Depth and direction of every contact, bit for bit.
::testing::AssertionResult same_estimates(const std::vector<Contact>& got, const std::vector<Contact>& want)
{
    if (got.size() != want.size()) return ::testing::AssertionFailure() << "sizes differ";
    for (size_t c = 0; c < got.size(); ++c) {
        bool same = same_bits(got[c].depth, want[c].depth);
        for (int k = 0; k < 3; ++k)
            same = same && same_bits(got[c].direction[k], want[c].direction[k]);
        if (!same)
            return ::testing::AssertionFailure()
                   << "contact " << c << " (vertex " << got[c].vertex << "): depth " << got[c].depth << " vs "
                   << want[c].depth << ", direction (" << got[c].direction[0] << ", " << got[c].direction[1] << ", "
                   << got[c].direction[2] << ") vs (" << want[c].direction[0] << ", " << want[c].direction[1] << ", "
                   << want[c].direction[2] << ")";
    }
    return ::testing::AssertionSuccess();
}

/// Trees built and refitted by a kept Penetration over a sequence of calls.
struct TreeCounts {
    std::int64_t built = 0, refitted = 0;
};

/// compute() and exact_depths() of `kept` (called before) at `x` against a Penetration made for this call
/// only: bit for bit the same, and the same counts of every kind of estimate. Adds kept's tree counts to `n`.
void check_against_fresh(Penetration& kept, const TetMesh& topology, const PositionsRef& x,
                         const std::vector<Contact>& contacts, TreeCounts& n)
{
    std::vector<Contact> a = contacts, b = contacts;
    PenetrationStats sa, sb;
    kept.compute(x, a, &sa);
    Penetration fresh;
    fresh.set_topology(topology);
    fresh.compute(x, b, &sb);
    EXPECT_TRUE(same_estimates(a, b));
    EXPECT_EQ(sa.pairs, sb.pairs);
    EXPECT_EQ(sa.border, sb.border);
    EXPECT_EQ(sa.propagated, sb.propagated);
    EXPECT_EQ(sa.fallback, sb.fallback);
    EXPECT_EQ(sa.intersections, sb.intersections);
    // The fresh one builds the tree of every penetrated object once; the kept one builds or refits each.
    EXPECT_EQ(sb.trees_refitted, 0);
    EXPECT_EQ(sa.trees_built + sa.trees_refitted, sb.trees_built);
    n.built += sa.trees_built;
    n.refitted += sa.trees_refitted;
    const std::vector<double> ea = kept.exact_depths(x, contacts), eb = fresh.exact_depths(x, contacts);
    ASSERT_EQ(ea.size(), eb.size());
    for (size_t c = 0; c < ea.size(); ++c)
        EXPECT_TRUE(same_bits(ea[c], eb[c])) << "exact depth of contact " << c << ": " << ea[c] << " vs " << eb[c];
}

/// Objects penetrated by some contact.
std::int64_t penetrated_objects(const std::vector<Contact>& contacts)
{
    std::vector<Index> o;
    for (const Contact& c : contacts)
        if (std::find(o.begin(), o.end(), c.tet_object) == o.end()) o.push_back(c.tet_object);
    return static_cast<std::int64_t>(o.size());
}

/// A TetGen .node/.ele pair (the first index of each file taken as the base), as one object.
std::optional<TetMesh> read_tetgen(const std::string& base)
{
    std::ifstream node(base + ".node"), ele(base + ".ele");
    if (!node || !ele) return std::nullopt;
    long nv = 0, dim = 0, na = 0, nb = 0;
    node >> nv >> dim >> na >> nb;
    if (!node || dim != 3 || nv <= 0) return std::nullopt;
    TetMesh m;
    m.positions.resize(nv, 3);
    long first = 0;
    for (long v = 0; v < nv; ++v) {
        long id = 0;
        node >> id >> m.positions(v, 0) >> m.positions(v, 1) >> m.positions(v, 2);
        if (v == 0) first = id;
        for (long k = 0; k < na + nb; ++k) {
            double skip = 0;
            node >> skip;
        }
    }
    long nt = 0, per = 0, ea = 0;
    ele >> nt >> per >> ea;
    if (!node || !ele || per != 4 || nt <= 0) return std::nullopt;
    m.tets.resize(nt, 4);
    for (long t = 0; t < nt; ++t) {
        long id = 0;
        ele >> id;
        for (int k = 0; k < 4; ++k) {
            long v = 0;
            ele >> v;
            m.tets(t, k) = static_cast<Index>(v - first);
        }
        for (long k = 0; k < ea; ++k) {
            double skip = 0;
            ele >> skip;
        }
    }
    if (!ele) return std::nullopt;
    return m;
}

} // namespace

TEST(CorePenetration, PlanarOverlapGivesExactDepthAndDirection)
{
    // B's left slab (x in [0.3, 0.5]) lies inside A; A's face x = 0.5 is the nearest boundary there.
    TetMesh m = box(4, 1.0, {0, 0, 0});
    m.ensure_object_ids();
    m.append(box(4, 1.0, {0.8, 0.05, 0.02}));
    std::vector<Contact> contacts = brute_contacts(m);
    ASSERT_FALSE(contacts.empty());
    PenetrationStats st;
    compute_penetration(m, contacts, &st);
    EXPECT_GT(st.border, 0);
    int checked = 0;
    for (const Contact& c : contacts) {
        ASSERT_TRUE(std::isfinite(c.depth));
        EXPECT_GE(c.depth, 0);
        EXPECT_NEAR(Eigen::Vector3d(c.direction[0], c.direction[1], c.direction[2]).norm(), 1.0, 1e-12);
        const Eigen::Vector3d p = m.positions.row(c.vertex).transpose();
        if (c.tet_object != 0 || std::abs(p.y()) > 0.25 || std::abs(p.z()) > 0.25) continue;
        // Near A's side faces the weighted average mixes in their normals (as the method does); away from
        // them every estimate comes from the face x = 0.5 and is exact.
        EXPECT_NEAR(c.depth, 0.5 - p.x(), 0.1) << "vertex " << c.vertex;
        EXPECT_GT(c.direction[0], 0.6);
        if (std::abs(p.y()) > 0.1 || std::abs(p.z()) > 0.1) continue;
        EXPECT_NEAR(c.depth, 0.5 - p.x(), 1e-9) << "vertex " << c.vertex;
        EXPECT_NEAR(c.direction[0], 1.0, 1e-9);
        ++checked;
    }
    EXPECT_GT(checked, 0);
    // Both objects penetrate each other: A's right slab inside B pushes the other way.
    bool other_way = false;
    for (const Contact& c : contacts)
        if (c.tet_object == 1) other_way = other_way || c.direction[0] < -0.99;
    EXPECT_TRUE(other_way);
}

TEST(CorePenetration, DeepVerticesAreValuedByPropagation)
{
    TetMesh m = box(5, 1.0, {0, 0, 0});
    m.ensure_object_ids();
    m.append(box(5, 1.0, {0.55, 0.0, 0.0})); // 0.45 overlap: several layers of colliding vertices
    std::vector<Contact> contacts = brute_contacts(m);
    PenetrationStats st;
    compute_penetration(m, contacts, &st);
    EXPECT_GT(st.propagated, 0);
    EXPECT_EQ(st.border + st.propagated + st.fallback, st.pairs);
    // Consistency: the depth of a B vertex inside A grows with its distance from A's face x = 0.5.
    for (const Contact& c : contacts) {
        const Eigen::Vector3d p = m.positions.row(c.vertex).transpose();
        if (c.tet_object != 0 || std::abs(p.y()) > 0.1 || std::abs(p.z()) > 0.1) continue;
        EXPECT_NEAR(c.depth, 0.5 - p.x(), 1e-9);
    }
}

TEST(CorePenetration, FullyEmbeddedObjectFallsBackToClosestPoint)
{
    TetMesh m = box(4, 1.0, {0, 0, 0});
    m.ensure_object_ids();
    m.append(box(1, 0.2, {0.25, 0.0, 0.0})); // entirely inside A: no border edge
    std::vector<Contact> contacts = brute_contacts(m);
    PenetrationStats st;
    compute_penetration(m, contacts, &st);
    std::vector<Index> inner; // B's vertices (all inside A) have no border edge: every one falls back
    for (const Contact& c : contacts)
        if (c.tet_object == 0 && std::find(inner.begin(), inner.end(), c.vertex) == inner.end())
            inner.push_back(c.vertex);
    EXPECT_GE(st.fallback, static_cast<std::int64_t>(inner.size()));
    for (const Contact& c : contacts) {
        if (c.tet_object != 0) continue;
        const Eigen::Vector3d p = m.positions.row(c.vertex).transpose();
        const double exact = 0.5 - p.cwiseAbs().maxCoeff();
        EXPECT_NEAR(c.depth, exact, 1e-9);
    }
}

TEST(CorePenetration, ExactDepthsAreDistancesToTheBoundary)
{
    TetMesh m = box(4, 1.0, {0, 0, 0});
    m.ensure_object_ids();
    m.append(box(3, 1.0, {0.7, 0.3, -0.2}));
    std::vector<Contact> contacts = brute_contacts(m);
    ASSERT_FALSE(contacts.empty());
    Penetration pen;
    pen.set_topology(m);
    const std::vector<double> exact = pen.exact_depths(m.positions, contacts);
    ASSERT_EQ(exact.size(), contacts.size());
    for (size_t i = 0; i < contacts.size(); ++i) {
        const Eigen::Vector3d p = m.positions.row(contacts[i].vertex).transpose();
        const Eigen::Vector3d centre =
            contacts[i].tet_object == 0 ? Eigen::Vector3d(0, 0, 0) : Eigen::Vector3d(0.7, 0.3, -0.2);
        const double expect = 0.5 - (p - centre).cwiseAbs().maxCoeff();
        EXPECT_NEAR(exact[i], std::max(0.0, expect), 1e-9);
    }
}

TEST(CorePenetration, BadInputIsRefused)
{
    Penetration pen;
    TetMesh m = box(1, 1.0, {0, 0, 0});
    std::vector<Contact> none;
    EXPECT_THROW(pen.compute(m.positions, none), Error);
    pen.set_topology(m);
    Positions wrong(3, 3);
    wrong.setZero();
    EXPECT_THROW(pen.compute(wrong, none), Error);
    std::vector<Contact> bad(1);
    bad[0].vertex = m.num_vertices() + 5;
    bad[0].tet_object = 0;
    try {
        pen.compute(m.positions, bad);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos);
    }
    Tets t(1, 4);
    t << 0, 1, 2, 99;
    EXPECT_THROW(pen.set_topology(t, 4), Error);
}

TEST(CorePenetration, KeptTreesGiveWhatAFreshPenetrationGives)
{
    // A deep overlap (border, propagation) and a small cube inside A (fallback); vertex coordinates on a
    // binary lattice at first, so that many edges meet the boundary exactly at shared face edges (ties).
    TetMesh m = box(4, 1.0, {0, 0, 0});
    m.ensure_object_ids();
    m.append(box(4, 1.0, {0.5, 0.0, 0.0}));
    m.append(box(1, 0.25, {-0.125, 0.0, 0.0}));
    const Positions rest = m.positions;
    Penetration kept;
    kept.set_topology(m);
    TreeCounts mild, strong;
    std::int64_t first_built = -1;
    // Mild motion: B slides and everything wobbles a little; the kept trees are refitted.
    for (int k = 0; k < 6; ++k) {
        for (Index v = 0; v < m.num_vertices(); ++v) {
            const Eigen::Vector3d r = rest.row(v).transpose();
            Eigen::Vector3d d = Eigen::Vector3d::Zero();
            if (k > 0) d = 0.004 * k * Eigen::Vector3d(std::sin(3 * r.y() + k), std::cos(2 * r.z()), std::sin(r.x()));
            if (m.vertex_object[static_cast<size_t>(v)] == 1) d.x() -= 0.03 * k;
            m.positions.row(v) = (r + d).transpose();
        }
        const std::vector<Contact> contacts = brute_contacts(m);
        ASSERT_FALSE(contacts.empty());
        TreeCounts n;
        check_against_fresh(kept, m, m.positions, contacts, n);
        if (k == 0) first_built = n.built;
        mild.built += n.built;
        mild.refitted += n.refitted;
    }
    EXPECT_GT(first_built, 0);
    EXPECT_EQ(mild.built, first_built); // only at the first call
    EXPECT_GT(mild.refitted, 0);
    // Strong deformation: A twisted more and more about z and squashed; refitted boxes grow loose and the
    // trees are rebuilt now and then, refitted in between.
    for (int k = 1; k <= 12; ++k) {
        for (Index v = 0; v < m.num_vertices(); ++v) {
            const Eigen::Vector3d r = rest.row(v).transpose();
            Eigen::Vector3d p = r;
            if (m.vertex_object[static_cast<size_t>(v)] != 1) {
                const double a = 0.5 * k * (r.z() + 0.5);
                p = Eigen::Vector3d(std::cos(a) * r.x() - std::sin(a) * r.y(),
                                    std::sin(a) * r.x() + std::cos(a) * r.y(), r.z() * (1 - 0.05 * k));
            } else {
                p.x() -= 0.1;
            }
            m.positions.row(v) = p.transpose();
        }
        const std::vector<Contact> contacts = brute_contacts(m);
        ASSERT_FALSE(contacts.empty());
        check_against_fresh(kept, m, m.positions, contacts, strong);
    }
    EXPECT_GT(strong.built, 0);
    EXPECT_GT(strong.refitted, 0);
}

TEST(CorePenetration, WarmComputeDoesNotAllocate)
{
    TetMesh m = box(4, 1.0, {0, 0, 0});
    m.ensure_object_ids();
    m.append(box(4, 1.0, {0.55, 0.02, 0.01}));
    const std::vector<Contact> contacts = brute_contacts(m);
    ASSERT_FALSE(contacts.empty());
    Penetration pen;
    pen.set_topology(m);
    std::vector<Contact> c = contacts;
    PenetrationStats st;
    pen.compute(m.positions, c, &st);
    ASSERT_GT(st.trees_built, 0);
    // The same contacts at moved positions, then fewer contacts: the trees are refitted, nothing allocated.
    Positions moved = m.positions;
    moved.col(1).array() += 0.01 * moved.col(0).array().sin();
    std::vector<Contact> fewer(contacts.begin(), contacts.begin() + static_cast<std::ptrdiff_t>(contacts.size() / 2));
    for (int pass = 0; pass < 2; ++pass) {
        std::span<Contact> todo = pass == 0 ? std::span<Contact>(c) : std::span<Contact>(fewer);
        g_allocations = 0;
        g_count_allocations = true;
        pen.compute(moved, todo, &st);
        g_count_allocations = false;
        EXPECT_EQ(g_allocations.load(), 0) << "pass " << pass;
        EXPECT_EQ(st.trees_built, 0);
        EXPECT_GT(st.trees_refitted, 0);
        EXPECT_GT(st.border, 0);
    }
}

TEST(CorePenetration, KeptTreesOnARealMeshGiveWhatAFreshPenetrationGives)
{
    const auto path = test::shared_mesh("armadillo_4k.node");
    if (!path) GTEST_SKIP() << "armadillo_4k not present";
    std::string base = path->string();
    base.resize(base.size() - 5);
    const std::optional<TetMesh> one = read_tetgen(base);
    ASSERT_TRUE(one.has_value());
    // Two copies, the second shifted by a fifth of the size; both bent by a motion growing over the calls.
    TetMesh m = *one;
    m.ensure_object_ids();
    TetMesh other = *one;
    const Eigen::RowVector3d lo = one->positions.colwise().minCoeff(), hi = one->positions.colwise().maxCoeff();
    const double size = (hi - lo).norm();
    other.positions.rowwise() += 0.2 * (hi - lo);
    m.append(other);
    const Positions rest = m.positions;
    const Index n = one->num_vertices();
    Penetration kept;
    kept.set_topology(m);
    Detector detector;
    detector.set_topology(m);
    TreeCounts counts;
    for (int k = 0; k < 8; ++k) {
        // Mild (refits), then strong and fine-grained (the refitted boxes grow loose: rebuilds).
        const double amp = k < 4 ? 0.002 * k : 0.05 * (k - 3), freq = k < 4 ? 6 : 30;
        for (Index v = 0; v < m.num_vertices(); ++v) {
            const Eigen::Vector3d r = (rest.row(v) - lo).transpose() / size;
            const double s = v < n ? 1.0 : -1.0;
            const Eigen::Vector3d d(std::sin(freq * r.y() + s * k), std::sin(freq * r.z() - k),
                                    std::cos(freq * r.x() * s));
            m.positions.row(v) = rest.row(v) + amp * size * d.transpose();
        }
        const std::vector<Contact> contacts = detector.detect(m.positions);
        ASSERT_FALSE(contacts.empty());
        check_against_fresh(kept, m, m.positions, contacts, counts);
    }
    EXPECT_GT(counts.refitted, 0);
    EXPECT_GT(counts.built, penetrated_objects(detector.contacts()));
}

TEST(CorePenetration, NewTopologyStartsWithNewTrees)
{
    TetMesh a = box(3, 1.0, {0, 0, 0});
    a.ensure_object_ids();
    a.append(box(3, 1.0, {0.6, 0.1, 0.0}));
    TetMesh b = box(4, 1.0, {0, 0, 0});
    b.ensure_object_ids();
    b.append(box(2, 0.5, {0.3, 0.0, 0.1}));
    b.append(box(3, 1.0, {-0.7, 0.0, 0.0}));
    Penetration pen;
    pen.set_topology(a);
    std::vector<Contact> ca = brute_contacts(a);
    pen.compute(a.positions, ca);
    const std::vector<Contact> cb = brute_contacts(b);
    ASSERT_FALSE(cb.empty());
    pen.set_topology(b);
    TreeCounts n;
    check_against_fresh(pen, b, b.positions, cb, n);
    EXPECT_EQ(n.refitted, 0);
    EXPECT_EQ(n.built, penetrated_objects(cb));
    EXPECT_GE(n.built, 2);
}
