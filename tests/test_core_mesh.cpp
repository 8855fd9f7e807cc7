// The mesh model: validation, reorientation, derived data (edges, boundary, adjacency, statistics, quality).
#include "support.hpp"
#include "tethash/error.hpp"
#include "tethash/geometry.hpp"
#include "tethash/mesh.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <set>

using namespace tethash;
using tethash::test::expect_error;

namespace {

TetMesh unit_tet()
{
    TetMesh m;
    m.positions.resize(4, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    m.tets.resize(1, 4);
    m.tets << 0, 1, 2, 3;
    return m;
}

/// A unit cube split into six positively oriented tets around the diagonal 0-6 (Kuhn subdivision).
TetMesh kuhn_cube()
{
    TetMesh m;
    m.positions.resize(8, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
    m.tets.resize(6, 4);
    m.tets << 0, 1, 2, 6, 0, 2, 3, 6, 0, 3, 7, 6, 0, 7, 4, 6, 0, 4, 5, 6, 0, 5, 1, 6;
    for (Index t = 0; t < 6; ++t)
        if (signed_volume(m.positions, {m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3)}) < 0)
            std::swap(m.tets(t, 2), m.tets(t, 3));
    return m;
}

} // namespace

TEST(Mesh, SignedVolumeOfUnitTet)
{
    const TetMesh m = unit_tet();
    EXPECT_DOUBLE_EQ(signed_volume(m.positions, {0, 1, 2, 3}), 1.0 / 6.0);
    EXPECT_DOUBLE_EQ(signed_volume(m.positions, {0, 2, 1, 3}), -1.0 / 6.0);
}

TEST(Mesh, ValidCubeHasNoProblems)
{
    const TetMesh m = kuhn_cube();
    const ValidationReport r = validate(m);
    EXPECT_TRUE(r.ok());
    EXPECT_TRUE(r.problems().empty());
    EXPECT_EQ(r.inverted_tets, 0);
    EXPECT_EQ(r.unreferenced_vertices, 0);
    EXPECT_NEAR(volume_stats(m.positions, m.tets).total, 1.0, 1e-12);
}

TEST(Mesh, ValidationCountsEachKindOfProblem)
{
    TetMesh m = kuhn_cube();
    // vertex 8: unreferenced; vertex 9: NaN (referenced by tet 7); tet 6: out of range; tet 8: repeated index;
    // tet 9: flat (four coplanar vertices); tet 1 inverted.
    m.positions.conservativeResize(12, 3);
    m.positions.row(8) << 5, 5, 5;
    m.positions.row(9) << std::nan(""), 0, 0;
    m.positions.row(10) << 2, 0, 0;
    m.positions.row(11) << 3, 0, 0;
    m.tets.conservativeResize(10, 4);
    m.tets.row(6) << 0, 1, 2, 12;
    m.tets.row(7) << 0, 1, 2, 9;
    m.tets.row(8) << 0, 1, 1, 2;
    m.tets.row(9) << 0, 1, 10, 11;
    std::swap(m.tets(1, 0), m.tets(1, 1));
    const ValidationReport r = validate(m);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.index_out_of_range, 1);
    EXPECT_EQ(r.repeated_index, 1);
    EXPECT_EQ(r.non_finite, 1);
    EXPECT_EQ(r.unreferenced_vertices, 1);
    EXPECT_EQ(r.degenerate_tets, 1);
    EXPECT_EQ(r.inverted_tets, 1);
    EXPECT_EQ(r.problems().size(), 6u);
    const std::set<Index> bad(r.first_bad_tets.begin(), r.first_bad_tets.end());
    EXPECT_TRUE(bad.count(1) && bad.count(6) && bad.count(8) && bad.count(9));
}

TEST(Mesh, NonManifoldFaceIsReported)
{
    TetMesh m = unit_tet();
    m.positions.conservativeResize(6, 3);
    m.positions.row(4) << 0.2, 0.2, -1;
    m.positions.row(5) << 0.3, 0.3, -2;
    m.tets.conservativeResize(3, 4);
    m.tets.row(1) << 0, 2, 1, 4;
    m.tets.row(2) << 0, 2, 1, 5; // third tet on face (0,1,2)
    EXPECT_EQ(validate(m).non_manifold_faces, 1);
}

TEST(Mesh, ReorientFixesInvertedTetsOnly)
{
    TetMesh m = kuhn_cube();
    std::swap(m.tets(2, 1), m.tets(2, 2));
    std::swap(m.tets(4, 0), m.tets(4, 3));
    EXPECT_EQ(validate(m).inverted_tets, 2);
    EXPECT_EQ(reorient_inverted(m), 2);
    EXPECT_EQ(validate(m).inverted_tets, 0);
    EXPECT_EQ(reorient_inverted(m), 0);
}

TEST(Mesh, UniqueEdges)
{
    EXPECT_EQ(unique_edges(unit_tet().tets).rows(), 6);
    const Edges e = unique_edges(kuhn_cube().tets);
    EXPECT_EQ(e.rows(), 19); // 12 cube edges + 6 face diagonals + 1 body diagonal
    for (Eigen::Index i = 0; i < e.rows(); ++i)
        EXPECT_LT(e(i, 0), e(i, 1));
}

TEST(Mesh, BoundaryFacesAreOutward)
{
    const TetMesh m = kuhn_cube();
    const Triangles f = boundary_faces(m.tets);
    ASSERT_EQ(f.rows(), 12); // two triangles per cube face
    const Eigen::Vector3d centre(0.5, 0.5, 0.5);
    double area = 0;
    for (Eigen::Index i = 0; i < f.rows(); ++i) {
        const Eigen::Vector3d a = m.positions.row(f(i, 0)), b = m.positions.row(f(i, 1)), c = m.positions.row(f(i, 2));
        const Eigen::Vector3d n = (b - a).cross(c - a);
        EXPECT_GT(n.dot((a + b + c) / 3 - centre), 0) << "face " << i << " points inward";
        area += 0.5 * n.norm();
    }
    EXPECT_NEAR(area, 6.0, 1e-12);
}

TEST(Mesh, AdjacencyIsSymmetric)
{
    const TetMesh m = kuhn_cube();
    const Adjacency a = vertex_adjacency(m.tets, m.num_vertices());
    ASSERT_EQ(a.offsets.size(), 9u);
    EXPECT_EQ(a.neighbours.size(), 2u * 19u);
    EXPECT_EQ(a.offsets[1] - a.offsets[0], 7); // vertex 0 is on the body diagonal: linked to all others
    for (Index u = 0; u < 8; ++u)
        for (Index k = a.offsets[u]; k < a.offsets[u + 1]; ++k) {
            const Index v = a.neighbours[k];
            const auto first = a.neighbours.begin() + a.offsets[v], last = a.neighbours.begin() + a.offsets[v + 1];
            EXPECT_TRUE(std::binary_search(first, last, u));
        }
    const Adjacency vt = vertex_tets(m.tets, m.num_vertices());
    EXPECT_EQ(vt.offsets[1] - vt.offsets[0], 6);
    EXPECT_EQ(vt.neighbours.size(), 24u);
}

TEST(Mesh, EdgeStats)
{
    const EdgeStats s = edge_stats(unit_tet().positions, unit_tet().tets);
    EXPECT_EQ(s.count, 6);
    EXPECT_DOUBLE_EQ(s.min, 1.0);
    EXPECT_DOUBLE_EQ(s.max, std::sqrt(2.0));
    EXPECT_NEAR(s.mean, (3 + 3 * std::sqrt(2.0)) / 6, 1e-15);
}

TEST(Mesh, QualityOfRegularAndSliverTets)
{
    Positions p(4, 3);
    p << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
    const TetQuality q = tet_quality(p, {0, 1, 2, 3});
    const double regular = std::acos(1.0 / 3.0) * 180 / M_PI;
    EXPECT_NEAR(q.min_dihedral_deg, regular, 1e-9);
    EXPECT_NEAR(q.max_dihedral_deg, regular, 1e-9);
    EXPECT_NEAR(q.aspect_ratio, 1.0, 1e-12);
    p.row(3) << 1.0 / 3, 1.0 / 3, -1.0 / 3 - 1e-3; // nearly in the plane of the others: a flat "cap"
    const TetQuality s = tet_quality(p, {0, 1, 2, 3});
    EXPECT_LT(s.min_dihedral_deg, 1.0);
    EXPECT_GT(s.max_dihedral_deg, 179.0);
    EXPECT_GT(s.aspect_ratio, 100.0);
}

TEST(Mesh, AppendMakesObjects)
{
    TetMesh a = unit_tet();
    TetMesh b = kuhn_cube();
    a.append(b);
    EXPECT_EQ(a.num_vertices(), 12);
    EXPECT_EQ(a.num_tets(), 7);
    EXPECT_EQ(a.num_objects(), 2);
    EXPECT_EQ(a.vertex_object[3], 0);
    EXPECT_EQ(a.vertex_object[4], 1);
    EXPECT_EQ(a.tet_object[6], 1);
    EXPECT_EQ(a.tets(1, 0), b.tets(0, 0) + 4);
    EXPECT_NO_THROW(a.check_consistency());
}

TEST(Mesh, ConsistencyCheckNamesTheTet)
{
    TetMesh m = kuhn_cube();
    m.tets(3, 2) = 42;
    expect_error([&] { m.check_consistency("cube.msh"); }, {"cube.msh", "tet 3", "42"});
}

// ---- split_objects_by_label -------------------------------------------------------------

namespace {

/// Two disjoint unit tets (vertices 0-3 and 4-7) plus an unreferenced vertex 8.
TetMesh two_separate_tets()
{
    TetMesh m;
    m.positions.resize(9, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1, 9, 9, 9;
    m.tets.resize(2, 4);
    m.tets << 0, 1, 2, 3, 4, 5, 6, 7;
    return m;
}

} // namespace

TEST(MeshLabels, EachLabelIsAnObjectInLabelOrder)
{
    TetMesh m = two_separate_tets();
    m.tet_label = {9, 3};
    const LabelSplit s = split_objects_by_label(m);
    ASSERT_EQ(s.object_labels.size(), 2u);
    EXPECT_EQ(s.object_labels[0], std::vector<Index>{3});
    EXPECT_EQ(s.object_labels[1], std::vector<Index>{9});
    EXPECT_EQ(s.shared_vertices, 0);
    EXPECT_EQ(m.tet_object, (std::vector<Index>{1, 0}));
    EXPECT_EQ(m.vertex_object, (std::vector<Index>{1, 1, 1, 1, 0, 0, 0, 0, 0})); // unreferenced vertex 8: object 0
    EXPECT_EQ(m.num_objects(), 2);
    EXPECT_EQ(m.tet_label, (std::vector<Index>{9, 3})); // labels kept
}

TEST(MeshLabels, WithoutLabelsOneObject)
{
    TetMesh m = two_separate_tets();
    m.vertex_object.assign(9, 4); // stale ids are replaced
    const LabelSplit s = split_objects_by_label(m);
    EXPECT_EQ(s.object_labels.size(), 1u);
    EXPECT_EQ(m.vertex_object, std::vector<Index>(9, 0));
    EXPECT_EQ(m.tet_object, std::vector<Index>(2, 0));
}

TEST(MeshLabels, SharedVertexIsAnErrorNamingItOrJoinsTheLabels)
{
    TetMesh m = kuhn_cube();
    m.tet_label = {1, 1, 1, 2, 2, 2}; // tets 0-2 and 3-5 share vertices 0, 6 and one more each side
    expect_error(
        [&] {
            TetMesh copy = m;
            split_objects_by_label(copy, SharedLabelVertices::error, "cube.msh");
        },
        {"cube.msh", "vertex ", "label 1", "label 2"});
    const LabelSplit s = split_objects_by_label(m, SharedLabelVertices::join);
    ASSERT_EQ(s.object_labels.size(), 1u);
    EXPECT_EQ(s.object_labels[0], (std::vector<Index>{1, 2}));
    // Vertices used by both halves, counted independently of the implementation.
    std::set<Index> first, second;
    for (Index t = 0; t < 6; ++t)
        for (int k = 0; k < 4; ++k)
            (t < 3 ? first : second).insert(m.tets(t, k));
    std::int64_t both = 0;
    for (Index v : first)
        both += second.count(v);
    EXPECT_EQ(s.shared_vertices, both);
    EXPECT_EQ(m.num_objects(), 1);
}

TEST(MeshLabels, JoinMergesOnlyLabelsThatTouch)
{
    // Labels 5 and 7 share vertex 3 (via a third tet); label 6 stands apart.
    TetMesh m = two_separate_tets();
    Positions p(10, 3);
    p << m.positions, -1, -1, -1;
    m.positions = p;
    m.tets.resize(3, 4);
    m.tets << 0, 1, 2, 3, 4, 5, 6, 7, 9, 1, 2, 3;
    m.tet_label = {5, 6, 7};
    const LabelSplit s = split_objects_by_label(m, SharedLabelVertices::join);
    ASSERT_EQ(s.object_labels.size(), 2u);
    EXPECT_EQ(s.object_labels[0], (std::vector<Index>{5, 7}));
    EXPECT_EQ(s.object_labels[1], (std::vector<Index>{6}));
    EXPECT_EQ(m.tet_object, (std::vector<Index>{0, 1, 0}));
    EXPECT_EQ(m.vertex_object[9], 0);
    EXPECT_EQ(m.vertex_object[4], 1);
    EXPECT_EQ(s.shared_vertices, 3);
}

TEST(Geometry, ClosestPointOnTriangleRegions)
{
    const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    EXPECT_TRUE(closest_point_on_triangle({-1, -1, 3}, a, b, c).isApprox(a));                           // vertex region
    EXPECT_TRUE(closest_point_on_triangle({2, -0.5, 0}, a, b, c).isApprox(b));                          // vertex region
    EXPECT_TRUE(closest_point_on_triangle({0.5, -2, 1}, a, b, c).isApprox(Eigen::Vector3d(0.5, 0, 0))); // edge ab
    EXPECT_TRUE(closest_point_on_triangle({1, 1, 0}, a, b, c).isApprox(Eigen::Vector3d(0.5, 0.5, 0)));  // edge bc
    EXPECT_TRUE(closest_point_on_triangle({0.2, 0.3, -4}, a, b, c).isApprox(Eigen::Vector3d(0.2, 0.3, 0))); // face
    // A zero-area triangle answers with a point of it, never NaN.
    const Eigen::Vector3d q = closest_point_on_triangle({0.5, 1, 0}, a, b, Eigen::Vector3d(2, 0, 0));
    EXPECT_TRUE(q.allFinite());
    EXPECT_NEAR(q.y(), 0.0, 1e-12);
}
