// Every broad phase (DetectParams::method) against the brute-force oracle: the same contacts bit for bit over the
// scenes of the hash's own tests (random, inverted, lattice-aligned, offset, coincident, collapsed, object rules),
// over each method's parameters, over moving scenes (structures kept across calls: refits, sweep orders, static
// parts) and over thread counts.
#include "../src/core/broad_phase/broad_phase.hpp"
#include "../src/core/broad_phase/inside_batch.hpp"
#include "../src/core/simd.hpp"
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/predicates.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>

using namespace tethash;
using namespace tethash::test;

namespace {

std::vector<Contact> run_oracle(const Scene& s, OracleStats* stats = nullptr)
{
    return brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects, stats);
}

/// Parameter variants per method: cell sizes for the grids, depths and leaf sizes for the trees, looseness,
/// levels, 1 and 2 threads; combined differently per seed.
std::vector<DetectParams> variants(Method method, std::uint32_t seed)
{
    const double cells[] = {0.3, 1.0, 2.5, 1.0 / 8};
    const int depths[] = {0, 1, 3, 12};
    const int leaves[] = {0, 1, 4, 64};
    const double loose[] = {0, 1, 1.5, 4};
    const int levels[] = {0, 1, 2, 6};
    std::vector<DetectParams> out;
    for (unsigned k = 0; k < 4; ++k) {
        DetectParams p;
        p.method = method;
        p.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
        p.cell_size = cells[(k + seed) % 4];
        p.partition.max_depth = depths[(k + 2 * seed) % 4];
        p.partition.leaf_size = leaves[(k + 3 * seed) % 4];
        p.partition.looseness = loose[(k + seed) % 4];
        p.partition.levels = levels[(k + 5 * seed) % 4];
        p.threads = 1 + static_cast<int>(k % 2);
        out.push_back(p);
    }
    return out;
}

std::string describe(const DetectParams& p)
{
    return std::string(to_string(p.method)) + " cell ×" + std::to_string(p.cell_size) + " depth " +
           std::to_string(p.partition.max_depth) + " leaf " + std::to_string(p.partition.leaf_size) + " loose " +
           std::to_string(p.partition.looseness) + " levels " + std::to_string(p.partition.levels) + " threads " +
           std::to_string(p.threads);
}

/// Every method and variant on scene `s` equals the oracle; with and without statistics the same contacts.
/// Returns the oracle's count of degenerate tets.
std::int64_t check_scene(const Scene& s, std::uint32_t seed, const std::string& what)
{
    OracleStats os;
    const std::vector<Contact> want = run_oracle(s, &os);
    for (Method method : all_methods())
        for (const DetectParams& p : variants(method, seed)) {
            Detector det(p);
            det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
            const std::vector<Contact> lean = det.detect(s.positions);
            DetectStats st;
            const std::vector<Contact>& full = det.detect(s.positions, &st);
            EXPECT_TRUE(same_contacts(full, want)) << what << " seed " << seed << ": " << describe(p);
            EXPECT_TRUE(identical(lean, full)) << what << ": " << describe(p) << ": with and without statistics";
            EXPECT_EQ(st.contacts, static_cast<std::int64_t>(want.size()));
            EXPECT_EQ(st.degenerate_tets, os.degenerate_tets) << what << ": " << describe(p);
            EXPECT_GE(st.candidates, st.contacts) << describe(p);
        }
    return os.degenerate_tets;
}

} // namespace

TEST(CorePartitions, RandomDeformedAndInverted)
{
    for (std::uint32_t seed = 1; seed <= 4; ++seed)
        check_scene(test::random_scene(seed, 3 + seed % 3, 3, 0.3), seed, "random");
    for (std::uint32_t seed = 20; seed < 23; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 1.2);
        for (Eigen::Index t = 0; t < s.tets.rows(); t += 7)
            std::swap(s.tets(t, 0), s.tets(t, 1));
        check_scene(s, seed, "inverted");
    }
}

TEST(CorePartitions, LatticeAlignedContactsOnFacesEdgesCorners)
{
    const double h = 0.25;
    const Eigen::Vector3d shifts[] = {{h / 2, 0, 0}, {h / 2, h / 2, h / 2}, {h, h, 0}, {0, 0, 0}};
    const Eigen::Vector3d origins[] = {{0, 0, 0}, {1e6, 1e6, -1e6}};
    std::uint32_t seed = 0;
    for (const auto& o : origins)
        for (const auto& sh : shifts) {
            const Scene s = test::lattice_pair(3, h, sh, o);
            ASSERT_FALSE(run_oracle(s).empty());
            check_scene(s, seed++, "lattice");
        }
}

TEST(CorePartitions, CoincidentVerticesFlatAndCollapsedTets)
{
    for (std::uint32_t seed = 40; seed < 43; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 0.3);
        s.positions.col(1).array() -= 12345.5;
        test::make_coincident(s, seed);
        for (Eigen::Index t = 2; t < s.tets.rows(); t += 37)
            s.tets(t, 3) = s.tets(t, t % 3);
        EXPECT_GT(check_scene(s, seed, "coincident"), 0) << "degenerate tets";
    }
}

TEST(CorePartitions, AllPointsEqualAndFlatScenes)
{
    // Zero extents everywhere (one point: every grid one cell, every tree box a point) and zero extent on one axis.
    // (One point: every candidate is an exact-arithmetic inside test of a flat tet, so a small scene.)
    Scene s = test::random_scene(60, 2, 1, 0.3);
    s.positions.rowwise() = Eigen::RowVector3d(-3.5, 1e6, 0.25);
    check_scene(s, 60, "one point");
    Scene flat = test::random_scene(61, 3, 2, 0.3);
    flat.positions.col(2).setConstant(-7.0);
    check_scene(flat, 61, "flat");
}

TEST(CorePartitions, SelfCollisionOffAndStaticObjects)
{
    for (std::uint32_t seed = 50; seed < 54; ++seed) {
        Scene s = test::random_scene(seed, 4, 3, 0.9);
        test::set_object_rules(s, seed);
        check_scene(s, seed, "objects");
    }
}

TEST(CorePartitions, TetSizesSpanningDecades)
{
    // Objects of cube edge 0.01, 0.1 and 1 overlapping: the case the hierarchical grid is for.
    Scene s = test::lattice_object(3, 3, 3, 0.01, Eigen::Vector3d(0.1, 0.1, 0.1));
    test::append_object(s, test::lattice_object(3, 3, 3, 0.1, Eigen::Vector3d(0.05, 0.05, 0.05)));
    test::append_object(s, test::lattice_object(2, 2, 2, 1.0, Eigen::Vector3d(-0.3, -0.2, -0.1)));
    ASSERT_FALSE(run_oracle(s).empty());
    check_scene(s, 7, "decades");
}

TEST(CorePartitions, MovingScenesKeepTheirStructuresExact)
{
    // Structures kept across calls (refitted trees, sort orders, static parts) must follow the motion: one object
    // flies through the others, the rest jitter, object 0 is static.
    Scene s = test::random_scene(81, 4, 3, 0.3);
    s.objects.resize(4);
    s.objects[0].is_static = true;
    for (Method method : all_methods()) {
        for (int threads : {1, 2}) {
            DetectParams p;
            p.method = method;
            p.threads = threads;
            Detector det(p);
            det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
            Scene moving = s;
            std::mt19937 rng(5);
            std::uniform_real_distribution<double> u(-0.02, 0.02);
            for (int step = 0; step < 8; ++step) {
                for (Eigen::Index v = 0; v < moving.positions.rows(); ++v) {
                    if (moving.vertex_object[static_cast<std::size_t>(v)] == 0) continue;
                    for (int a = 0; a < 3; ++a)
                        moving.positions(v, a) += u(rng);
                    if (moving.vertex_object[static_cast<std::size_t>(v)] == 3) moving.positions(v, 0) += 0.3;
                }
                EXPECT_TRUE(same_contacts(det.detect(moving.positions), run_oracle(moving)))
                    << to_string(method) << " threads " << threads << " step " << step;
            }
        }
    }
}

TEST(CorePartitions, DeterministicAcrossThreadCounts)
{
    const Scene s = test::random_scene(77, 8, 4, 0.4);
    for (Method method : all_methods()) {
        DetectParams p;
        p.method = method;
        p.threads = 1;
        Detector one(p);
        one.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
        const std::vector<Contact> a = one.detect(s.positions);
        ASSERT_FALSE(a.empty());
        for (int threads : {2, 3}) {
            p.threads = threads;
            Detector det(p);
            det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
            EXPECT_TRUE(identical(a, det.detect(s.positions))) << to_string(method) << " threads " << threads;
        }
    }
}

TEST(CorePartitions, EmptyAndSingleTetScenes)
{
    const Scene one = test::lattice_object(1, 1, 1, 1.0, Eigen::Vector3d::Zero());
    for (Method method : all_methods()) {
        DetectParams p;
        p.method = method;
        Detector det(p);
        det.set_topology(Tets(0, 4), 0);
        EXPECT_TRUE(det.detect(Positions(0, 3)).empty()) << to_string(method);
        det.set_topology(one.tets, static_cast<Index>(one.positions.rows()));
        EXPECT_TRUE(same_contacts(det.detect(one.positions), run_oracle(one))) << to_string(method);
    }
}

TEST(CorePartitions, NamesAndParameterErrors)
{
    for (Method m : all_methods())
        EXPECT_EQ(parse_method(to_string(m)), m);
    EXPECT_EQ(parse_method("auto"), Method::automatic);
    expect_error([] { parse_method("quadtree"); },
                 {"--method: unknown method 'quadtree' (expected one of hash, brute"});
    expect_error([] { parse_method("kd3", "scene.toml: method"); }, {"scene.toml: method: unknown method 'kd3'"});
    DetectParams p;
    p.partition.max_depth = 31;
    expect_error([&] { Detector d(p); }, {"max_depth must be 1..30"});
    p = DetectParams{};
    p.partition.looseness = 0.5;
    expect_error([&] { Detector d(p); }, {"looseness must be 1..16"});
    p = DetectParams{};
    p.partition.leaf_size = -1;
    expect_error([&] { Detector d(p); }, {"leaf_size must be ≥ 1"});
    p = DetectParams{};
    p.method = static_cast<Method>(99);
    expect_error([&] { Detector d(p); }, {"method out of range"});
}

TEST(CorePartitions, UniformGridRefusesGridsBeyondItsMemoryLimit)
{
    // Two unit cubes 1000 apart with cells of 0.001: 10^18 cells. The error names the cells and bytes and the way out.
    Scene s = test::lattice_object(1, 1, 1, 1.0, Eigen::Vector3d::Zero());
    test::append_object(s, test::lattice_object(1, 1, 1, 1.0, Eigen::Vector3d(1000, 1000, 1000)));
    DetectParams p;
    p.method = Method::uniform_grid;
    p.cell_size_mode = DetectParams::CellSizeMode::absolute;
    p.cell_size = 1e-3;
    Detector det(p);
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    expect_error([&] { det.detect(s.positions); },
                 {"uniform grid", "cells (1001001 × 1001001 × 1001001)", "bytes", "larger cell size", "hash"});
    // The same scene with cells of 10: 101^3 cells, stated in the statistics.
    p.cell_size = 10;
    det.set_params(p);
    DetectStats st;
    EXPECT_TRUE(same_contacts(det.detect(s.positions, &st), run_oracle(s)));
    EXPECT_EQ(st.nodes, 101 * 101 * 101);
    EXPECT_GT(st.memory_bytes, 101 * 101 * 101 * 4);
}

namespace {

/// The broad phase's candidate pairs, sorted.
std::vector<std::pair<Index, Index>> candidates(detail::BroadPhase& bp, const detail::PartitionScene& scene)
{
    std::vector<detail::CandidateSink> sinks(1);
    bp.find(scene, sinks);
    std::vector<std::pair<Index, Index>> out;
    for (const detail::CandidatePair& c : sinks[0].pairs)
        out.emplace_back(c.vertex, c.tet);
    std::sort(out.begin(), out.end());
    return out;
}

detail::PartitionScene partition_scene(const Scene& s, const std::vector<unsigned char>& tet_static,
                                       const std::vector<Index>& moving)
{
    detail::PartitionScene scene;
    scene.positions = s.positions.data();
    scene.num_vertices = static_cast<Index>(s.positions.rows());
    scene.tets = s.tets.data();
    scene.num_tets = static_cast<Index>(s.tets.rows());
    scene.moving_vertices = moving;
    scene.tet_static = tet_static.data();
    return scene;
}

} // namespace

TEST(CorePartitions, RefittedBvhAndSweepFollowTheMotionAndRebuildWhenDegraded)
{
    // Small motions: the refitted tree is kept and the sweep's orders are repaired by insertion sort; the objects
    // then scatter and turn (strong motion): the refitted tree degrades and is rebuilt. Every step the candidates
    // equal the rebuilt tree's, and the contacts the oracle's.
    Scene s = test::random_scene(91, 6, 3, 0.3);
    const std::vector<unsigned char> tet_static(static_cast<std::size_t>(s.tets.rows()), 0);
    std::vector<Index> moving(static_cast<std::size_t>(s.positions.rows()));
    for (std::size_t v = 0; v < moving.size(); ++v)
        moving[v] = static_cast<Index>(v);
    const auto refit = detail::make_bvh(true), rebuilt = detail::make_bvh(false);
    const auto sweep = detail::make_sort_sweep();
    DetectParams p;
    p.method = Method::bvh_refit;
    Detector det(p);
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    std::int64_t builds_after_small = 0;
    for (int step = 0; step < 30; ++step) {
        const bool strong = step >= 10;
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
            const int o = s.vertex_object[static_cast<std::size_t>(v)];
            for (int a = 0; a < 3; ++a)
                s.positions(v, a) += 0.002 * u(rng) + (strong ? 0.15 * std::sin(o + 2.0 * a) : 0.0);
        }
        if (strong) // turn every object about its first vertex, each by its own angle
            for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
                const int o = s.vertex_object[static_cast<std::size_t>(v)];
                const Eigen::Index first =
                    std::find(s.vertex_object.begin(), s.vertex_object.end(), o) - s.vertex_object.begin();
                const Eigen::Vector3d c = s.positions.row(first).transpose();
                const Eigen::Matrix3d r = Eigen::AngleAxisd(0.3 * (o + 1), Eigen::Vector3d::UnitZ()).toRotationMatrix();
                s.positions.row(v) = (r * (s.positions.row(v).transpose() - c) + c).transpose();
            }
        detail::PartitionScene scene = partition_scene(s, tet_static, moving);
        scene.first = step == 0;
        const auto want = candidates(*rebuilt, scene);
        EXPECT_EQ(candidates(*refit, scene), want) << "step " << step;
        EXPECT_EQ(candidates(*sweep, scene), want) << "step " << step;
        EXPECT_TRUE(same_contacts(det.detect(s.positions), run_oracle(s))) << "step " << step;
        if (step == 9) {
            builds_after_small = refit->counts().builds;
            EXPECT_EQ(builds_after_small, 1) << "small motions refit the first tree";
            EXPECT_EQ(sweep->counts().builds, 1) << "small motions repair the first order";
            EXPECT_EQ(sweep->counts().updates, 9);
        }
    }
    EXPECT_GT(refit->counts().builds, builds_after_small) << "strong motion degrades the tree: rebuilt";
    EXPECT_LT(refit->counts().builds, 30) << "not rebuilt on every step";
    EXPECT_EQ(refit->counts().updates, 29) << "every later call refits first";
}

TEST(CorePartitions, BatchedInsideTestIsTheOraclesBitForBit)
{
    // inside_tets (four pairs per step with the AVX2 kernels, TETHASH_SIMD=scalar: one at a time) against
    // predicates::inside_tet pair by pair: the same answer, the same barycentric coordinates bit for bit and at most
    // the same count of exact evaluations (fewer with AVX2), on every (vertex, tet) pair of scenes with random,
    // inverted and flat tets and of lattice-aligned ones (vertices exactly on faces, edges and corners: the undecided
    // lanes).
    Scene flat = test::random_scene(5, 3, 2, 0.3);
    test::make_coincident(flat, 5);
    const Scene scenes[] = {test::random_scene(3, 3, 2, 0.4), flat,
                            test::lattice_pair(2, 0.5, Eigen::Vector3d(0.25, 0, 0.5), Eigen::Vector3d(1, -2, 0.5))};
    std::int64_t exact_total = 0, want_exact_total = 0;
    for (const Scene& s : scenes) {
        const Index n = static_cast<Index>(s.positions.rows()), m = static_cast<Index>(s.tets.rows());
        std::vector<Index> vertex, tet;
        for (Index t = 0; t < m; ++t)
            for (Index v = 0; v < n; ++v) {
                vertex.push_back(v);
                tet.push_back(t);
            }
        const auto count = static_cast<std::int32_t>(vertex.size());
        const Positions& P = s.positions;
        const std::vector<Index> tets(s.tets.data(), s.tets.data() + s.tets.size());
        std::vector<std::uint8_t> inside(vertex.size());
        std::vector<double> bary(4 * vertex.size());
        const std::int64_t exact =
            detail::inside_tets(P.data(), tets.data(), vertex.data(), tet.data(), count, inside.data(), bary.data());
        std::int64_t want_exact = 0, insides = 0;
        for (std::int32_t j = 0; j < count; ++j) {
            const Index* tv = tets.data() + 4 * static_cast<std::size_t>(tet[static_cast<std::size_t>(j)]);
            const predicates::InsideResult r = predicates::inside_tet(
                P.data() + 3 * static_cast<std::size_t>(vertex[static_cast<std::size_t>(j)]),
                P.data() + 3 * static_cast<std::size_t>(tv[0]), P.data() + 3 * static_cast<std::size_t>(tv[1]),
                P.data() + 3 * static_cast<std::size_t>(tv[2]), P.data() + 3 * static_cast<std::size_t>(tv[3]));
            want_exact += r.exact_evaluations;
            ASSERT_EQ(inside[static_cast<std::size_t>(j)] != 0, r.inside) << "pair " << j;
            if (!r.inside) continue;
            ++insides;
            for (int i = 0; i < 4; ++i)
                EXPECT_EQ(std::memcmp(&bary[4 * static_cast<std::size_t>(j) + static_cast<std::size_t>(i)], &r.bary[i],
                                      sizeof(double)),
                          0)
                    << "pair " << j << " bary[" << i << "] " << bary[4 * static_cast<std::size_t>(j) + i] << " vs "
                    << r.bary[i];
        }
        // Fewer exact evaluations where a lane's decided face rejects it (AVX2); pair by pair, inside_tet's own.
        EXPECT_LE(exact, want_exact);
        if (!detail::avx2_kernels()) {
            EXPECT_EQ(exact, want_exact);
        }
        exact_total += exact;
        want_exact_total += want_exact;
        EXPECT_GT(insides, 0);
        EXPECT_GT(want_exact, 0); // the lattice makes undecided pairs
    }
    if (detail::avx2_kernels()) {
        EXPECT_LT(exact_total, want_exact_total) << "outside lanes with an undecided face were evaluated exactly";
    }
}

TEST(CorePartitions, ATetsPairsTestedAtOnceAcrossBlocksAndWithoutNeedlessExactWork)
{
    // One big tet (its face 0, opposite its first vertex, in the plane z = 0) over 2,500 tiny tets (edge 2^-10, each
    // the corner of a cube at a point of a 25 × 25 × 4 lattice of spacing 0.5), all with exactly representable
    // coordinates: more than 1,024 of their vertices lie in the closed big tet, so the pairs of one tet that pass its
    // face planes fill more than one block of the oracle's test (1,024); the vertices on the planes of its faces are
    // undecided by the floating-point filters. Every method, at 1 and 2 threads: the oracle's contacts bit for bit.
    // The vertices in z = 0 outside the big tet's face 0 are rejected by another face without the exact evaluation of
    // face 0 that the oracle makes first: the methods that query tet by tet, which here test the big tet's pairs
    // against its face planes at once, make fewer exact evaluations than the oracle (scalar or AVX2); the others,
    // pair by pair, at most as many.
    Scene s;
    s.positions.resize(4, 3);
    s.positions << 0, 0, 12, 0, 0, 0, 12, 0, 0, 0, 12, 0;
    s.tets.resize(1, 4);
    s.tets << 0, 1, 2, 3;
    s.vertex_object.assign(4, 0);
    s.tet_object.assign(1, 0);
    Scene tiny;
    const double e = 1.0 / 1024;
    tiny.positions.resize(4 * 2500, 3);
    tiny.tets.resize(2500, 4);
    Index t = 0;
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 25; ++j)
            for (int i = 0; i < 25; ++i, ++t) {
                const double x = 0.5 * i, y = 0.5 * j, z = 0.5 * k;
                tiny.positions.middleRows(4 * t, 4) << x, y, z, x + e, y, z, x, y + e, z, x, y, z + e;
                tiny.tets.row(t) << 4 * t, 4 * t + 1, 4 * t + 2, 4 * t + 3;
            }
    append_object(s, tiny);
    OracleStats os;
    const std::vector<Contact> want = run_oracle(s, &os);
    std::int64_t in_big_tet = 0;
    for (const Contact& c : want)
        in_big_tet += c.tet == 0;
    ASSERT_GT(in_big_tet, 1100);
    for (Method method : all_methods()) {
        if (method == Method::hash || method == Method::automatic) continue;
        for (int threads : {1, 2}) {
            DetectParams p;
            p.method = method;
            p.threads = threads;
            p.cell_size_mode = DetectParams::CellSizeMode::absolute; // not the mean edge: the tiny tets'
            p.cell_size = 1;
            Detector det(p);
            det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
            DetectStats st;
            EXPECT_TRUE(identical(det.detect(s.positions, &st), want)) << to_string(method) << " threads " << threads;
            const bool by_vertex = method == Method::hierarchical_grid || method == Method::octree_loose ||
                                   method == Method::bvh || method == Method::bvh_refit;
            if (by_vertex)
                EXPECT_LE(st.exact_fallbacks, os.exact_evaluations) << to_string(method);
            else
                EXPECT_LT(st.exact_fallbacks, os.exact_evaluations) << to_string(method);
        }
    }
}
