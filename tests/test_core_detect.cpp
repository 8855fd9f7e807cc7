// Detector vs the brute-force oracle over many seeded scenes and every parameter kind; determinism;
// object rules; API errors.
#include "../src/core/hash/hash_grid.hpp"
#include "../src/core/hash/scan.hpp"
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/predicates.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>

using namespace tethash;
using namespace tethash::test;

namespace {

/// Runs the detector without statistics (the lean scan kernel) and with them (every entry classified):
/// both must give the same contacts bit for bit; returns them.
std::vector<Contact> run_detector(const Scene& s, const DetectParams& p, DetectStats* stats = nullptr)
{
    Detector det(p);
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    const std::vector<Contact> lean = det.detect(s.positions);
    DetectStats local;
    const std::vector<Contact>& full = det.detect(s.positions, stats ? stats : &local);
    EXPECT_TRUE(identical(lean, full)) << "contacts with and without statistics differ";
    return full;
}

std::vector<Contact> run_oracle(const Scene& s, OracleStats* stats = nullptr)
{
    return brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects, stats);
}

/// Parameter sets for one scene (cell size as a factor of the mean edge).
std::vector<DetectParams> variants(std::uint32_t seed)
{
    // Every kind appears for every scene: 5 cell sizes, 6 table sizes, both hashes, 1 and 2 threads,
    // combined differently per seed (the full product would be slow at 1/20 cells).
    const double cells[] = {1.0 / 20, 0.3, 1.0, 2.5, 20.0};
    const std::int64_t tables[] = {0, 1, 2, 97, 1024, 1 << 20};
    std::vector<DetectParams> out;
    for (unsigned k = 0; k < 12; ++k)
        out.push_back({.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge,
                       .cell_size = cells[(k + seed) % 5],
                       .table_size = tables[(k + 3 * seed) % 6],
                       .hash = (k + seed) % 2 ? HashFunction::teschner : HashFunction::column,
                       .threads = 1 + static_cast<int>((k / 2) % 2)});
    return out;
}

void check_scene(const Scene& s, std::uint32_t seed, const std::string& what)
{
    OracleStats os;
    const std::vector<Contact> want = run_oracle(s, &os);
    for (const DetectParams& p : variants(seed)) {
        DetectStats st;
        const std::vector<Contact> got = run_detector(s, p, &st);
        EXPECT_TRUE(same_contacts(got, want))
            << what << " seed " << seed << " cell ×" << p.cell_size << " table " << p.table_size << " hash "
            << to_string(p.hash) << " threads " << p.threads;
        EXPECT_EQ(st.degenerate_tets, os.degenerate_tets) << what;
        EXPECT_EQ(st.contacts, static_cast<std::int64_t>(want.size()));
    }
}

} // namespace

TEST(CoreDetect, RandomDeformedOverlappingObjects)
{
    for (std::uint32_t seed = 1; seed <= 8; ++seed) {
        const Scene s = test::random_scene(seed, 3 + seed % 3, 3, 0.3);
        check_scene(s, seed, "random");
    }
}

TEST(CoreDetect, StronglyDeformedWithInvertedTets)
{
    for (std::uint32_t seed = 20; seed < 26; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 1.2); // jitter beyond half a cell: many inverted tets
        // Explicitly inverted tets: swap two indices of every 7th tet.
        for (Eigen::Index t = 0; t < s.tets.rows(); t += 7)
            std::swap(s.tets(t, 0), s.tets(t, 1));
        check_scene(s, seed, "inverted");
    }
}

TEST(CoreDetect, LatticeAlignedContactsOnFacesEdgesCorners)
{
    const double h = 0.25; // exactly representable lattice
    const Eigen::Vector3d shifts[] = {{h / 2, 0, 0}, {h / 2, h / 2, 0}, {h / 2, h / 2, h / 2},    {h, 0, 0},
                                      {h, h, 0},     {0, 0, 0},         {h / 4, h / 2, 3 * h / 4}};
    const Eigen::Vector3d origins[] = {{0, 0, 0}, {-37.0, -2.5, -0.75}, {1e6, 1e6, -1e6}};
    std::uint32_t seed = 0;
    for (const auto& o : origins)
        for (const auto& sh : shifts) {
            const Scene s = test::lattice_pair(3, h, sh, o);
            const std::vector<Contact> want = run_oracle(s);
            EXPECT_FALSE(want.empty());
            check_scene(s, seed++, "lattice");
        }
}

TEST(CoreDetect, OffsetAndNegativeCoordinates)
{
    for (std::uint32_t seed = 30; seed < 34; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 0.3);
        s.positions.col(0).array() += (seed % 2 ? 1e6 : -1e6);
        s.positions.col(1).array() -= 12345.5;
        check_scene(s, seed, "offset");
    }
}

TEST(CoreDetect, CoincidentVerticesAndFlatTets)
{
    for (std::uint32_t seed = 40; seed < 46; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 0.3);
        test::make_coincident(s, seed);
        // A vertex exactly at a corner of a tet of another object.
        s.positions.row(0) = s.positions.row(s.tets(s.tets.rows() - 1, 2)).eval();
        OracleStats os;
        run_oracle(s, &os);
        EXPECT_GT(os.degenerate_tets, 0);
        check_scene(s, seed, "coincident");
    }
}

TEST(CoreDetect, TetsWithARepeatedVertexAreSkippedAsDegenerate)
{
    for (std::uint32_t seed = 60; seed < 64; ++seed) {
        Scene s = test::random_scene(seed, 3, 3, 0.3);
        const OracleStats before = [&] {
            OracleStats os;
            run_oracle(s, &os);
            return os;
        }();
        // Collapsed tets as converters write them: one vertex index twice (and one three times).
        std::int64_t collapsed = 0;
        for (Eigen::Index t = 2; t < s.tets.rows(); t += 37, ++collapsed)
            s.tets(t, 3) = s.tets(t, t % 3);
        s.tets(0, 1) = s.tets(0, 2) = s.tets(0, 0);
        ++collapsed;
        OracleStats os;
        const std::vector<Contact> want = run_oracle(s, &os);
        EXPECT_EQ(os.degenerate_tets, before.degenerate_tets + collapsed) << seed;
        for (const Contact& c : want)
            EXPECT_TRUE(c.tet != 0 && (c.tet < 2 || (c.tet - 2) % 37 != 0)) << "contact in a collapsed tet";
        check_scene(s, seed, "collapsed"); // the detector agrees, degenerate count included
    }
}

TEST(CoreDetect, SelfCollisionOffAndStaticObjects)
{
    for (std::uint32_t seed = 50; seed < 56; ++seed) {
        Scene s = test::random_scene(seed, 4, 3, 0.9);
        test::set_object_rules(s, seed);
        const std::vector<Contact> want = run_oracle(s);
        for (const Contact& c : want) {
            EXPECT_FALSE(s.objects[c.vertex_object].is_static && s.objects[c.tet_object].is_static);
            if (c.vertex_object == c.tet_object) {
                EXPECT_TRUE(s.objects[c.vertex_object].self_collision);
            }
        }
        check_scene(s, seed, "objects");
        // The same scene with all options on has more contacts.
        Scene plain = s;
        plain.objects.clear();
        EXPECT_GT(run_oracle(plain).size(), want.size());
    }
}

TEST(CoreDetect, StaticObjectsHashedOnceStillExactWhenOthersMove)
{
    Scene s = test::random_scene(61, 3, 3, 0.3);
    s.objects.resize(3);
    s.objects[0].is_static = true;
    Detector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, s.objects);
    for (int step = 0; step < 4; ++step) {
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v)
            if (s.vertex_object[v] != 0) s.positions(v, 0) += 0.05 * step;
        EXPECT_TRUE(same_contacts(det.detect(s.positions), run_oracle(s))) << "step " << step;
    }
}

TEST(CoreDetect, DeterministicAcrossThreadsAndRepeats)
{
    const Scene s = test::random_scene(77, 8, 4, 0.4);
    DetectParams p;
    p.threads = 1;
    Detector one(p);
    one.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    const std::vector<Contact> a = one.detect(s.positions);
    ASSERT_FALSE(a.empty());
    for (int threads : {2, 3, 1}) {
        p.threads = threads;
        Detector det(p);
        det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
        for (int rep = 0; rep < 3; ++rep) {
            const std::vector<Contact>& b = det.detect(s.positions);
            ASSERT_EQ(a.size(), b.size());
            for (std::size_t i = 0; i < a.size(); ++i) {
                ASSERT_EQ(a[i].vertex, b[i].vertex);
                ASSERT_EQ(a[i].tet, b[i].tet);
                for (int k = 0; k < 4; ++k)
                    ASSERT_EQ(a[i].bary[k], b[i].bary[k]); // bitwise
            }
        }
    }
    for (std::size_t i = 1; i < a.size(); ++i)
        EXPECT_TRUE(a[i - 1].vertex < a[i].vertex || (a[i - 1].vertex == a[i].vertex && a[i - 1].tet < a[i].tet));
}

// Big enough (over 65,536 moving and 65,536 static vertices) that the vertex tables are built by the whole team
// (cells split by vertex, the counting sort split by bucket) and each thread radix-sorts its own contacts before
// the merge: the contacts must still be the same, bit for bit, for 1, 2 and 3 threads (3: uneven splits) and
// with statistics.
TEST(CoreDetect, TeamBuiltTablesAndMergeAreThreadCountIndependent)
{
    const Scene s = test::random_scene(91, 4, 32, 0.3); // 4 objects × 35,937 vertices
    ASSERT_GT(s.positions.rows(), 4 * 35000);
    const std::vector<ObjectOptions> objects = {{true, false}, {true, true}, {false, false}, {true, true}};
    std::vector<Contact> first;
    std::int64_t first_scanned = -1;
    for (int threads : {1, 2, 3}) {
        DetectParams p;
        p.threads = threads;
        Detector det(p);
        det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object, objects);
        DetectStats st;
        const std::vector<Contact> a = det.detect(s.positions, &st);
        const std::vector<Contact>& b = det.detect(s.positions);
        ASSERT_TRUE(identical(a, b)) << threads << " threads: with and without statistics differ";
        ASSERT_FALSE(a.empty());
        EXPECT_EQ(st.threads, threads);
        for (std::size_t i = 1; i < a.size(); ++i)
            ASSERT_TRUE(a[i - 1].vertex < a[i].vertex || (a[i - 1].vertex == a[i].vertex && a[i - 1].tet < a[i].tet));
        if (first.empty()) {
            first = a;
            first_scanned = st.entries_scanned;
        } else {
            EXPECT_TRUE(identical(first, a)) << threads << " threads differ from 1 thread";
            EXPECT_EQ(first_scanned, st.entries_scanned);
        }
    }
}

TEST(CoreDetect, SteadyStateKeepsBuffers)
{
    const Scene s = test::random_scene(5, 4, 3, 0.3);
    Detector det;
    det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object);
    det.detect(s.positions);
    const Contact* data = det.contacts().data();
    DetectStats st1, st2;
    det.detect(s.positions, &st1);
    det.detect(s.positions, &st2);
    EXPECT_EQ(det.contacts().data(), data); // the output array was not reallocated
    EXPECT_EQ(st1.memory_bytes, st2.memory_bytes);
    EXPECT_GT(st2.memory_bytes, 0);
    EXPECT_EQ(st2.entries_scanned, st2.hash_collisions + st2.box_rejections + st2.own_vertex_skips +
                                       (st2.inside_tests)); // no object rules here: every survivor is tested
    EXPECT_GE(st2.inside_tests, st2.contacts);
}

TEST(CoreDetect, AutoCellSizeIsMeanEdgeAndTableSizeDefaults)
{
    const Scene s = test::lattice_object(3, 3, 3, 0.5, Eigen::Vector3d::Zero());
    const double mean = mean_edge_length(s.positions, s.tets);
    // Kuhn cubes: axis edges 0.5, face diagonals 0.5√2, one body diagonal 0.5√3 per cube.
    EXPECT_GT(mean, 0.5);
    EXPECT_LT(mean, 0.5 * std::sqrt(3.0));
    DetectStats st;
    run_detector(s, DetectParams{}, &st);
    EXPECT_DOUBLE_EQ(st.cell_size, mean);
    EXPECT_EQ(st.table_size, auto_table_size(HashFunction::column, s.positions.rows()));
    EXPECT_EQ(auto_table_size(HashFunction::column, 1000), 2048);
    EXPECT_EQ(auto_table_size(HashFunction::teschner, 1000), 2003);
    DetectParams p;
    p.cell_size_mode = DetectParams::CellSizeMode::factor_of_mean_edge;
    p.cell_size = 2.0;
    run_detector(s, p, &st);
    EXPECT_DOUBLE_EQ(st.cell_size, 2 * mean);
    p.cell_size_mode = DetectParams::CellSizeMode::absolute;
    p.cell_size = 0.125;
    p.table_size = 13;
    run_detector(s, p, &st);
    EXPECT_EQ(st.cell_size, 0.125);
    EXPECT_EQ(st.table_size, 13);
}

TEST(CoreDetect, HashNames)
{
    EXPECT_EQ(parse_hash_function("teschner"), HashFunction::teschner);
    EXPECT_EQ(parse_hash_function("column"), HashFunction::column);
    EXPECT_STREQ(to_string(HashFunction::column), "column");
    expect_error([&] { parse_hash_function("md5"); }, {"md5"});
}

TEST(CoreDetect, ApiErrorsNameTheProblem)
{
    Scene s = test::lattice_object(1, 1, 1, 1.0, Eigen::Vector3d::Zero());
    const Index n = static_cast<Index>(s.positions.rows());
    DetectParams p;
    p.cell_size_mode = DetectParams::CellSizeMode::absolute;
    p.cell_size = 0;
    expect_error([&] { Detector d(p); }, {"cell_size"});
    p.cell_size = -1;
    expect_error([&] { Detector d(p); }, {"-1"});
    p.cell_size = std::nan("");
    expect_error([&] { Detector d(p); }, {"cell_size"});
    p = DetectParams{};
    p.table_size = -5;
    expect_error([&] { Detector d(p); }, {"table_size"});
    p.table_size = std::int64_t{1} << 40;
    expect_error([&] { Detector d(p); }, {"table_size"});
    p = DetectParams{};
    p.threads = -2;
    expect_error([&] { Detector d(p); }, {"threads"});

    Detector det;
    Tets bad = s.tets;
    bad(3, 2) = n;
    expect_error([&] { det.set_topology(bad, n); }, {"tet 3"});
    bad = s.tets;
    bad(2, 1) = -1;
    expect_error([&] { det.set_topology(bad, n); }, {"out of range"});
    std::vector<Index> short_obj(3, 0);
    expect_error([&] { det.set_topology(s.tets, n, short_obj); }, {"vertex_object"});
    std::vector<Index> neg(n, 0);
    neg[5] = -1;
    expect_error([&] { det.set_topology(s.tets, n, neg); }, {"vertex 5"});

    det.set_topology(s.tets, n);
    Positions wrong(n - 1, 3);
    wrong.setZero();
    expect_error([&] { det.detect(wrong); }, {"rows"});
    Positions nan = s.positions;
    nan(6, 1) = std::nan("");
    expect_error([&] { det.detect(nan); }, {"vertex 6"});
    det.detect(s.positions);
    expect_error([&] { det.detect(nan); }, {"vertex 6"}); // also after the first call
    Positions inf = s.positions;
    inf(2, 2) = INFINITY;
    expect_error([&] { det.detect(inf); }, {"vertex 2"});
    expect_error([&] { brute_force_contacts(nan, s.tets); }, {"vertex 6"});

    // Huge coordinates or tiny cells: a clear error, no wrap-around.
    p = DetectParams{};
    p.cell_size_mode = DetectParams::CellSizeMode::absolute;
    p.cell_size = 1e-12;
    Detector tiny(p);
    tiny.set_topology(s.tets, n);
    Positions far = s.positions;
    far.array() += 1e6;
    expect_error([&] { tiny.detect(far); }, {"cell size"});
    Detector d2;
    d2.set_topology(s.tets, n);
    Positions huge = s.positions * 1e300;
    expect_error([&] { d2.detect(huge); }, {"cell"});
}

TEST(CoreDetect, EmptyInputs)
{
    Detector det;
    Tets none(0, 4);
    det.set_topology(none, 0);
    Positions p(0, 3);
    EXPECT_TRUE(det.detect(p).empty());
    det.set_topology(none, 5);
    Positions five = Positions::Random(5, 3);
    EXPECT_TRUE(det.detect(five).empty());
}

TEST(CoreDetect, LongTetsAndAliasedCellKeys)
{
    // A needle tet spanning 2000 cells in z (beyond the 32-bit cell key's exact window: exact cells are compared),
    // and small tets whose vertices lie on the needle's axis, on its faces, or in cells that share a needle cell's
    // key (2^10 cells up in z, inside the needle's box at cell size 1; 2^11 cells over in x or y) and, for table
    // sizes 1 and 1024, its buckets. At cell size 4 the needle spans 501 cells: the key test applies.
    Scene s;
    std::vector<Eigen::Vector3d> pts = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {1, 1, 2000}};
    std::vector<std::array<Index, 4>> tets = {{0, 1, 2, 3}};
    s.vertex_object = {0, 0, 0, 0};
    s.tet_object = {0};
    auto small_tet = [&](const Eigen::Vector3d& p) {
        const Index b = static_cast<Index>(pts.size());
        for (const Eigen::Vector3d& d : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.25, 0, 0),
                                         Eigen::Vector3d(0, 0.25, 0), Eigen::Vector3d(0, 0, 0.25)}) {
            pts.push_back(p + d);
            s.vertex_object.push_back(1);
        }
        tets.push_back({b, b + 1, b + 2, b + 3});
        s.tet_object.push_back(1);
    };
    for (double z = 0; z <= 2000; z += 24.75) {
        const double f = 1.0 - z / 2000; // the needle's cross-section shrinks linearly towards its tip
        small_tet({z / 2000 + 0.5 * f, z / 2000 + 0.5 * f, z}); // inside
        small_tet({z / 2000, z / 2000 + 2.0 * f, z});           // on the face x = z/2000 (exactly, when representable)
        small_tet({0.5, 0.5, z + 1024});                        // same key as a needle cell, far above
        small_tet({0.5 + 2048, 0.5, z});
        small_tet({0.5, 0.5 - 2048, z});
    }
    s.positions = test::matrix_of<Positions>(pts);
    s.tets = test::matrix_of<Tets>(tets);
    const std::vector<Contact> want = run_oracle(s);
    ASSERT_GT(want.size(), 80u);
    for (double cell : {1.0, 4.0})
        for (std::int64_t table : {0, 1, 1024, 4096})
            for (HashFunction hash : {HashFunction::column, HashFunction::teschner})
                for (int threads : {1, 2}) {
                    DetectParams p;
                    p.cell_size_mode = DetectParams::CellSizeMode::absolute;
                    p.cell_size = cell;
                    p.table_size = table;
                    p.hash = hash;
                    p.threads = threads;
                    EXPECT_TRUE(same_contacts(run_detector(s, p), want))
                        << "cell " << cell << " table " << table << " hash " << to_string(hash) << " threads "
                        << threads;
                }
}

TEST(CoreDetect, LeanColumnPathFallsBackPerTetAndTable)
{
    // Without statistics the column hash runs stage 2's lean path, which hands a tet to the general one when its
    // cell box is too big for the keys (a needle over 1000 cells in z) or for the range array, or, table by table,
    // when its z-run is as long as the table: here the small static object's table (16 buckets) against a needle of
    // about 100 cells whose moving-table candidates are already appended. Contacts as the oracle's, with and without
    // a skin, at 1 and 2 threads, and as with statistics (run_detector: the general path alone).
    Scene s = test::random_scene(28, 3, 3, 0.9);
    test::append_object(s, test::lattice_object(1, 1, 1, 0.3, Eigen::Vector3d(-0.1, -0.2, 0.0))); // static
    Scene needles;
    // Two needles: about 100 cells long in z (longer than the static table) and about 1000 (beyond the keys' window).
    const std::vector<Eigen::Vector3d> needle_points = {{0.0, 0.0, -1.0},  {0.3, 0.0, -1.0},  {0.0, 0.3, -1.0},
                                                        {0.1, 0.1, 20.0},  {-0.3, 0.1, -1.5}, {0.0, 0.1, -1.5},
                                                        {-0.3, 0.4, -1.5}, {-0.2, 0.2, 200.0}};
    needles.positions = test::matrix_of<Positions>(needle_points);
    needles.tets = test::matrix_of<Tets>(std::vector<std::array<Index, 4>>{{0, 1, 2, 3}, {4, 5, 6, 7}});
    needles.vertex_object.assign(8, 0);
    needles.tet_object.assign(2, 0);
    test::append_object(s, needles);
    s.objects.resize(5);
    s.objects[3].is_static = true;
    s.objects[1].self_collision = false;
    const std::vector<Contact> want = run_oracle(s);
    ASSERT_GT(want.size(), 50u);
    // The needles and the static object meet the scene.
    EXPECT_TRUE(std::any_of(want.begin(), want.end(), [&](const Contact& c) { return c.tet_object == 3; }));
    EXPECT_TRUE(std::any_of(want.begin(), want.end(), [&](const Contact& c) { return c.tet_object == 4; }));
    for (std::int64_t table : {0, 2, 1024})
        for (double skin : {0.0, 0.05})
            for (int threads : {1, 2}) {
                DetectParams p;
                p.cell_size_mode = DetectParams::CellSizeMode::absolute;
                p.cell_size = 0.2;
                p.table_size = table;
                p.skin = skin;
                p.threads = threads;
                Detector det(p);
                det.set_topology(s.tets, static_cast<Index>(s.positions.rows()), s.vertex_object, s.tet_object,
                                 s.objects);
                // Twice: with a skin the second call reuses the kept candidates of the first.
                for (int call = 0; call < 2; ++call)
                    EXPECT_TRUE(same_contacts(det.detect(s.positions), want))
                        << "table " << table << " skin " << skin << " threads " << threads << " call " << call;
                EXPECT_TRUE(same_contacts(run_detector(s, p), want)) << "table " << table;
            }
}

TEST(CoreDetect, ScanKernelFollowsTethashSimd)
{
    test::expect_kernel_follows_tethash_simd(detail::scan_kernel_name());
}

TEST(CoreDetect, PlaneFilterKeepsExactlyWhatItCannotRejectInOrder)
{
    // filter_candidates (the kernel TETHASH_SIMD chooses) against exact orientations: a candidate it leaves out is
    // outside the closed tet; every candidate inside or on it is kept, in input order, with its index; a face left
    // out of a kept candidate's undecided mask has the exact sign of its value. Points on the tets' faces and edges
    // (up to rounding) and at their corners make the undecided cases.
    std::mt19937 rng(28);
    std::uniform_real_distribution<double> u(-1, 1);
    std::uniform_int_distribution<int> pick(0, 3);
    int kept_total = 0, undecided_total = 0, left_out_total = 0;
    for (int trial = 0; trial < 200; ++trial) {
        Positions P(64 + 4, 3);
        for (int v = 0; v < 4; ++v)
            P.row(v) = Eigen::RowVector3d(u(rng), u(rng), u(rng));
        if (trial % 4 == 0) P.row(3) = (P.row(0) + P.row(1) + P.row(2)) / 3.0; // a flat tet: skipped below
        for (int i = 4; i < P.rows(); ++i) {
            const double w0 = u(rng), w1 = u(rng), w2 = u(rng);
            switch (i % 4) {
            case 0: { // on a face, up to rounding: three corners weighted a, b, 1 - a - b
                const int k = pick(rng);
                const double a = 0.25 * (w0 + 1), b = 0.25 * (w1 + 1);
                P.row(i) = a * P.row(k) + b * P.row((k + 1) % 4) + (1 - a - b) * P.row((k + 2) % 4);
                break;
            }
            case 1: // a corner
                P.row(i) = P.row(pick(rng));
                break;
            case 2: // an edge point
                P.row(i) = P.row(0) + 0.5 * (w1 + 1) * (P.row(1) - P.row(0));
                break;
            default:
                P.row(i) = Eigen::RowVector3d(w0, w1, w2);
            }
        }
        const double* A = P.data();
        const double *B = A + 3, *C = A + 6, *D = A + 9;
        detail::FacePlanes f;
        bool exact = false;
        const int sign = detail::face_planes(A, B, C, D, f, exact);
        EXPECT_EQ(sign, predicates::orient3d_exact(A, B, C, D).sign);
        if (sign == 0) continue;
        std::vector<Index> cand;
        for (Index i = 4; i < P.rows(); ++i)
            cand.push_back(i);
        const auto n = static_cast<std::int32_t>(cand.size());
        std::vector<double> val(4 * cand.size());
        std::vector<std::int8_t> code(cand.size());
        std::vector<std::int32_t> kept(cand.size());
        const std::int32_t k =
            detail::filter_candidates(f, P.data(), cand.data(), n, val.data(), code.data(), kept.data());
        ASSERT_LE(k, n);
        std::int32_t next = 0; // the next kept entry to match
        for (std::int32_t j = 0; j < n; ++j) {
            const double* p = P.data() + 3 * static_cast<std::size_t>(cand[static_cast<std::size_t>(j)]);
            const int s0 = predicates::orient3d_exact(p, B, C, D).sign * sign;
            const int s1 = predicates::orient3d_exact(A, p, C, D).sign * sign;
            const int s2 = predicates::orient3d_exact(A, B, p, D).sign * sign;
            const int s3 = predicates::orient3d_exact(A, B, C, p).sign * sign;
            const int exact_sign[4] = {s0, s1, s2, s3};
            const bool inside = s0 >= 0 && s1 >= 0 && s2 >= 0 && s3 >= 0;
            if (next < k && kept[static_cast<std::size_t>(next)] == j) {
                for (int i = 0; i < 4; ++i) {
                    if (code[static_cast<std::size_t>(next)] & (1 << i)) continue;
                    const double v = val[4 * static_cast<std::size_t>(next) + static_cast<std::size_t>(i)];
                    EXPECT_EQ(v > 0 ? 1 : (v < 0 ? -1 : 0), exact_sign[i]) << "trial " << trial << " face " << i;
                }
                undecided_total += code[static_cast<std::size_t>(next)] != 0;
                ++next;
                ++kept_total;
            } else {
                EXPECT_FALSE(inside) << "trial " << trial << " candidate " << j << " left out but inside";
                ++left_out_total;
            }
        }
        EXPECT_EQ(next, k) << "kept indices out of order or out of range";
    }
    // The scenes exercise every outcome.
    EXPECT_GT(kept_total, 0);
    EXPECT_GT(undecided_total, 0);
    EXPECT_GT(left_out_total, 0);
}

TEST(CoreDetectParams, NumbersAreWholeStringsAndFinite)
{
    EXPECT_EQ(tethash::parse_number("0.25", "--dt"), 0.25);
    EXPECT_EQ(tethash::parse_number("-1e3", "--dt"), -1000.0);
    EXPECT_EQ(tethash::parse_integer("-7", "--substeps"), -7);
    for (const char* bad : {"", " 1", "1 ", "1x", "nan", "inf", "1e999", "x2"})
        try {
            tethash::parse_number(bad, "--dt");
            ADD_FAILURE() << "accepted '" << bad << "'";
        } catch (const tethash::Error& e) {
            EXPECT_EQ(std::string(e.what()), std::string("--dt: expected a number, found '") + bad + "'");
        }
    for (const char* bad : {"", "1.5", "2 ", "99999999999999999999"})
        EXPECT_THROW(tethash::parse_integer(bad, "--substeps"), tethash::Error) << bad;
}
