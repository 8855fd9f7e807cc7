// meshing/tetrahedralize.hpp: signed-distance functions and closed surfaces to tets on the BCC lattice.
#include "support.hpp"
#include "surface_support.hpp"

#include "tethash/error.hpp"
#include "tethash/mesh.hpp"
#include "tethash/meshing/tetrahedralize.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <numbers>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace tethash;
using namespace tethash::test;

namespace {

bool bit_identical(const TetMesh& a, const TetMesh& b)
{
    return a.tets == b.tets && a.positions.rows() == b.positions.rows() &&
           std::memcmp(a.positions.data(), b.positions.data(),
                       sizeof(double) * static_cast<std::size_t>(a.positions.size())) == 0;
}

} // namespace

TEST(Tetrahedralize, RecoversTheVolumeOfAGeneratedSphere)
{
    const io::SurfaceMesh s = sphere_surface(16);
    const double expect = enclosed_volume(s);
    const TetMesh m = meshing::tetrahedralize(s, {16, true});
    EXPECT_NEAR(volume(m), expect, 0.03 * expect);
    const ValidationReport r = validate(m);
    EXPECT_TRUE(r.ok());
    EXPECT_EQ(r.inverted_tets, 0);
    EXPECT_EQ(r.degenerate_tets, 0);
    EXPECT_EQ(r.unreferenced_vertices, 0);
    // Deterministic.
    const TetMesh again = meshing::tetrahedralize(s, {16, true});
    EXPECT_TRUE(again.positions == m.positions);
    EXPECT_TRUE(again.tets == m.tets);
}

TEST(Tetrahedralize, ToleratesAHoleAndAnInwardOrientation)
{
    io::SurfaceMesh s = sphere_surface(12);
    const double expect = enclosed_volume(s);
    // Cut two triangles out: a small hole.
    io::SurfaceMesh holed = s;
    holed.triangles = s.triangles.bottomRows(s.triangles.rows() - 2);
    const TetMesh m = meshing::tetrahedralize(holed, {12, true});
    EXPECT_NEAR(volume(m), expect, 0.05 * expect);
    EXPECT_EQ(validate(m).inverted_tets, 0);
    // Every triangle flipped.
    io::SurfaceMesh flipped = s;
    flipped.triangles.col(1).swap(flipped.triangles.col(2));
    EXPECT_NEAR(volume(meshing::tetrahedralize(flipped, {12, true})), expect, 0.05 * expect);
}

TEST(Tetrahedralize, RejectsSurfacesWithoutInside)
{
    io::SurfaceMesh tri;
    tri.vertices.resize(3, 3);
    tri.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0.5;
    tri.triangles.resize(1, 3);
    tri.triangles << 0, 1, 2;
    expect_error([&] { meshing::tetrahedralize(tri, {8, true}); }, {"nothing is inside"});
    io::SurfaceMesh empty;
    EXPECT_THROW(meshing::tetrahedralize(empty, {8, true}), Error);
    tri.triangles << 0, 1, 7;
    expect_error([&] { meshing::tetrahedralize(tri, {8, true}); }, {"triangle 0"});
    EXPECT_THROW(meshing::tetrahedralize(sphere_surface(4), {0, true}), Error);
}

TEST(TetrahedralizeSdf, CustomFunctionAndEmptyInside)
{
    // A ball of radius 0.3 off-centre in a 1-box.
    auto ball = [](const Eigen::Vector3d& p) { return (p - Eigen::Vector3d(0.1, 0, 0)).norm() - 0.3; };
    const TetMesh m =
        meshing::tetrahedralize_sdf(ball, Eigen::Vector3d(-0.2, -0.3, -0.3), Eigen::Vector3d(0.4, 0.3, 0.3), 16, true);
    const double expect = 4.0 / 3.0 * std::numbers::pi * 0.027;
    EXPECT_NEAR(volume(m), expect, 0.03 * expect);
    EXPECT_EQ(validate(m).inverted_tets, 0);
    // Everything outside: an error that says so.
    auto nothing = [](const Eigen::Vector3d&) { return 1.0; };
    expect_error(
        [&] { meshing::tetrahedralize_sdf(nothing, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 4, true); },
        {"nothing is inside"});
    EXPECT_THROW(meshing::tetrahedralize_sdf(ball, Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 1), 4, true), Error);
}

TEST(Tetrahedralize, BitIdenticalAtOneAndTwoThreads)
{
#ifndef _OPENMP
    GTEST_SKIP() << "built without OpenMP";
#else
    // The inside tests, the snapping targets and the winding numbers run in parallel loops.
    const io::SurfaceMesh s = sphere_surface(12);
    auto ball = [](const Eigen::Vector3d& p) { return (p - Eigen::Vector3d(0.1, 0, 0)).norm() - 0.3; };
    const int saved = omp_get_max_threads();
    TetMesh surface[2], sdf[2];
    for (int threads : {1, 2}) {
        omp_set_num_threads(threads);
        surface[threads - 1] = meshing::tetrahedralize(s, {14, true});
        sdf[threads - 1] = meshing::tetrahedralize_sdf(ball, Eigen::Vector3d(-0.2, -0.3, -0.3),
                                                       Eigen::Vector3d(0.4, 0.3, 0.3), 14, true);
    }
    omp_set_num_threads(saved);
    ASSERT_GT(surface[0].num_tets(), 1000);
    EXPECT_TRUE(bit_identical(surface[0], surface[1]));
    EXPECT_TRUE(bit_identical(sdf[0], sdf[1]));
#endif
}
