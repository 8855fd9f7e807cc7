// Tests of meshing/generate.hpp: shapes on the BCC lattice validate, are deterministic, have the analytic
// volume, keep good tets, and reject bad parameters.
#include "support.hpp"
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"
#include "tethash/meshing/generate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace tethash;
using tethash::test::expect_error;

namespace {

double volume(const TetMesh& m)
{
    return volume_stats(m.positions, m.tets).total;
}

std::pair<double, double> dihedral_range(const TetMesh& m)
{
    double lo = 180, hi = 0;
    for (Index t = 0; t < m.num_tets(); ++t) {
        const TetQuality q = tet_quality(m.positions, {m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3)});
        lo = std::min(lo, q.min_dihedral_deg);
        hi = std::max(hi, q.max_dihedral_deg);
    }
    return {lo, hi};
}

double min_signed_volume(const TetMesh& m)
{
    double v = 1e300;
    for (Index t = 0; t < m.num_tets(); ++t)
        v = std::min(v, signed_volume(m.positions, {m.tets(t, 0), m.tets(t, 1), m.tets(t, 2), m.tets(t, 3)}));
    return v;
}

/// Boundary edges not in exactly two boundary triangles, plus boundary vertices whose boundary
/// triangles form more than one edge-connected fan.
long boundary_manifold_problems(const TetMesh& m)
{
    const Triangles bf = boundary_faces(m.tets);
    long bad = 0;
    std::map<std::pair<Index, Index>, int> edge_count;
    for (Eigen::Index i = 0; i < bf.rows(); ++i)
        for (int k = 0; k < 3; ++k) {
            const Index a = bf(i, k), b = bf(i, (k + 1) % 3);
            ++edge_count[{std::min(a, b), std::max(a, b)}];
        }
    for (const auto& [e, c] : edge_count)
        if (c != 2) ++bad;
    std::vector<std::vector<Eigen::Index>> around(static_cast<std::size_t>(m.num_vertices()));
    for (Eigen::Index i = 0; i < bf.rows(); ++i)
        for (int k = 0; k < 3; ++k)
            around[static_cast<std::size_t>(bf(i, k))].push_back(i);
    for (Index v = 0; v < m.num_vertices(); ++v) {
        const auto& tris = around[static_cast<std::size_t>(v)];
        std::vector<std::size_t> parent(tris.size());
        std::iota(parent.begin(), parent.end(), std::size_t{0});
        auto find = [&](std::size_t x) {
            while (parent[x] != x)
                x = parent[x] = parent[parent[x]];
            return x;
        };
        for (std::size_t a = 0; a < tris.size(); ++a)
            for (std::size_t b = a + 1; b < tris.size(); ++b)
                for (int x = 0; x < 3; ++x)
                    for (int y = 0; y < 3; ++y)
                        if (bf(tris[a], x) == bf(tris[b], y) && bf(tris[a], x) != v) parent[find(a)] = find(b);
        std::size_t fans = 0;
        for (std::size_t a = 0; a < tris.size(); ++a)
            if (find(a) == a) ++fans;
        if (fans > 1) ++bad;
    }
    return bad;
}

meshing::GenerateParams params(const std::string& shape, int resolution, bool snap = true)
{
    meshing::GenerateParams p;
    p.shape = shape;
    p.resolution = resolution;
    p.snap = snap;
    return p;
}

} // namespace

TEST(Generate, EveryShapeValidatesSnappedAndUnsnapped)
{
    for (const std::string& shape : meshing::generate_shapes())
        for (bool snap : {false, true})
            for (int res : {8, 12}) {
                SCOPED_TRACE(shape + " resolution " + std::to_string(res) + (snap ? " snapped" : ""));
                const TetMesh m = meshing::generate(params(shape, res, snap));
                ASSERT_GT(m.num_tets(), 0);
                EXPECT_EQ(validate(m).problems(), std::vector<std::string>()); // no problem of any kind
                EXPECT_GT(min_signed_volume(m), 0.0);
                EXPECT_EQ(boundary_manifold_problems(m), 0);
            }
}

TEST(Generate, ShapesAreListedWithTheirSizes)
{
    const auto names = meshing::generate_shapes();
    for (const char* required : {"box", "bar", "sphere", "torus", "cylinder", "capsule"})
        EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
    EXPECT_EQ(names.size(), meshing::shape_catalog().size());
    const Eigen::Vector3d bar = meshing::shape_natural_size("bar");
    EXPECT_DOUBLE_EQ(bar.x(), 4 * bar.y());
    EXPECT_THROW(meshing::shape_natural_size("nope"), Error);
}

TEST(Generate, IsDeterministic)
{
    for (const char* shape : {"sphere", "blob", "torus"}) {
        const TetMesh a = meshing::generate(params(shape, 14));
        const TetMesh b = meshing::generate(params(shape, 14));
        ASSERT_EQ(a.num_vertices(), b.num_vertices()) << shape;
        ASSERT_EQ(a.num_tets(), b.num_tets()) << shape;
        EXPECT_TRUE(a.tets == b.tets) << shape;
        // Bit for bit: compare the raw bytes, not within a tolerance.
        EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(),
                                 sizeof(double) * static_cast<std::size_t>(a.positions.size())))
            << shape;
    }
}

TEST(Generate, BitIdenticalAtOneAndTwoThreads)
{
#ifndef _OPENMP
    GTEST_SKIP() << "built without OpenMP";
#else
    // The inside test and the snapping targets run in parallel loops; the mesh must not depend on it.
    const int saved = omp_get_max_threads();
    for (const char* shape : {"sphere", "blob", "box"}) {
        TetMesh m[2];
        for (int threads : {1, 2}) {
            omp_set_num_threads(threads);
            m[threads - 1] = meshing::generate(params(shape, 14));
        }
        ASSERT_EQ(m[0].num_vertices(), m[1].num_vertices()) << shape;
        EXPECT_TRUE(m[0].tets == m[1].tets) << shape;
        EXPECT_EQ(0, std::memcmp(m[0].positions.data(), m[1].positions.data(),
                                 sizeof(double) * static_cast<std::size_t>(m[0].positions.size())))
            << shape;
    }
    omp_set_num_threads(saved);
#endif
}

TEST(Generate, VolumesMatchTheAnalyticShapes)
{
    const double pi = std::numbers::pi;
    // Snapped meshes: within a few per cent at moderate resolution.
    EXPECT_NEAR(volume(meshing::generate(params("sphere", 24))), 4.0 / 3.0 * pi * 0.125,
                0.02 * (4.0 / 3.0 * pi * 0.125));
    const double torus = 2 * pi * pi * 0.35 * 0.15 * 0.15;
    EXPECT_NEAR(volume(meshing::generate(params("torus", 32))), torus, 0.03 * torus);
    EXPECT_NEAR(volume(meshing::generate(params("cylinder", 20))), pi * 0.25, 0.03 * pi * 0.25);
    const double capsule = pi * 0.0625 * 1.0 + 4.0 / 3.0 * pi * 0.25 * 0.25 * 0.25;
    EXPECT_NEAR(volume(meshing::generate(params("capsule", 24))), capsule, 0.03 * capsule);
    // Boxes snap exactly, including edges and corners, for any size.
    EXPECT_NEAR(volume(meshing::generate(params("box", 7))), 1.0, 1e-9);
    EXPECT_NEAR(volume(meshing::generate(params("bar", 16))), 4.0, 1e-9);
    meshing::GenerateParams p = params("box", 9);
    p.size = Eigen::Vector3d(1, 2, 3);
    EXPECT_NEAR(volume(meshing::generate(p)), 6.0, 1e-9);
    // Unsnapped, the sphere is a staircase: still close, but it is the snapping that gets within 1 %.
    const double unsnapped = volume(meshing::generate(params("sphere", 24, false)));
    EXPECT_NEAR(unsnapped, 4.0 / 3.0 * pi * 0.125, 0.06 * (4.0 / 3.0 * pi * 0.125));
}

TEST(Generate, SizeAndScaleSetTheBoundingBox)
{
    meshing::GenerateParams p = params("sphere", 16);
    p.size = Eigen::Vector3d(2, 1, 1);
    p.scale = 3;
    const TetMesh m = meshing::generate(p);
    const auto [lo, hi] = bounding_box(m.positions);
    const Eigen::Vector3d ext = hi - lo;
    EXPECT_NEAR(ext.x(), 6.0, 0.15);
    EXPECT_NEAR(ext.y(), 3.0, 0.15);
    EXPECT_NEAR(ext.z(), 3.0, 0.15);
    EXPECT_NEAR(0.5 * (lo + hi).norm(), 0.0, 0.1); // centred at the origin
    // Ellipsoid of semi-axes 3, 1.5, 1.5.
    const double expect = 4.0 / 3.0 * std::numbers::pi * 3 * 1.5 * 1.5;
    EXPECT_NEAR(volume(m), expect, 0.03 * expect);

    meshing::GenerateParams bar = params("bar", 8);
    bar.scale = 0.5;
    const auto [blo, bhi] = bounding_box(meshing::generate(bar).positions);
    EXPECT_NEAR(bhi.x() - blo.x(), 2.0, 1e-9);
    EXPECT_NEAR(bhi.y() - blo.y(), 0.5, 1e-9);
}

TEST(Generate, TetQualityStaysBounded)
{
    // The unsnapped BCC lattice of a cube-proportioned shape: every dihedral angle is 60 or 90 degrees.
    const auto [lo, hi] = dihedral_range(meshing::generate(params("sphere", 12, false)));
    EXPECT_NEAR(lo, 60.0, 1e-6);
    EXPECT_NEAR(hi, 90.0, 1e-6);
    // Snapping never goes below the 10-degree guard; boxes keep far better tets.
    for (const std::string& shape : meshing::generate_shapes()) {
        const auto [slo, shi] = dihedral_range(meshing::generate(params(shape, 12)));
        EXPECT_GE(slo, 10.0) << shape;
        EXPECT_LT(shi, 170.0) << shape;
    }
    EXPECT_GE(dihedral_range(meshing::generate(params("box", 10))).first, 40.0);
}

TEST(Generate, ResolutionSetsTheCellCountAlongTheLongestExtent)
{
    // Mean edge length ~ h: doubling the resolution halves it.
    const TetMesh a = meshing::generate(params("bar", 8, false));
    const TetMesh b = meshing::generate(params("bar", 16, false));
    const double ea = edge_stats(a.positions, a.tets).mean, eb = edge_stats(b.positions, b.tets).mean;
    EXPECT_NEAR(ea / eb, 2.0, 0.2);
    EXPECT_NEAR(ea, 4.0 / 8 * 0.9, 0.15); // BCC edges: h·√3/2 and h, mean ≈ 0.9 h
}

TEST(Generate, RejectsBadParameters)
{
    expect_error([&] { meshing::generate(params("dodecahedron", 8)); }, {"unknown shape 'dodecahedron'", "sphere"});
    expect_error([&] { meshing::generate(params("box", 0)); }, {"resolution 0"});
    meshing::GenerateParams p = params("box", 4);
    p.scale = -1;
    EXPECT_THROW(meshing::generate(p), Error);
    p.scale = 1;
    p.size = Eigen::Vector3d(1, 0, 1);
    EXPECT_THROW(meshing::generate(p), Error);
}
