// Consistent penetration depth (Heidelberger et al. 2004): exact on planar boundaries, propagation,
// the closest-point fallback, the exact-distance reference, and bad input.
#include "core_scenes.hpp"
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/penetration.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

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
