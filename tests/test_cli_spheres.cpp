// tethash study spheres: the spheres experiment end to end on a small run (files, every method's colliding
// pairs equal brute force's in every frame, brute force's test count, the tree methods test fewer pairs,
// figures, bad options).
#include "support.hpp"

#include "tethash/study/table.hpp"

#include <map>
#include <set>
#include <string>

namespace tethash {
namespace {

using study::Table;
using test::expect_refused;
using test::quote;
using test::run_tethash;

std::string cell(const Table& t, const study::Row& r, const char* column)
{
    const int k = t.index_of(column);
    EXPECT_GE(k, 0) << column;
    return k < 0 ? std::string() : r[static_cast<std::size_t>(k)];
}

TEST(CliSpheres, EveryMethodFindsBruteForcesPairsInEveryFrame)
{
    const auto dir = test::temp_dir();
    const int spheres = 60, frames = 80;
    std::string args = "study spheres --radius 0.08 --depths 2,5 --no-plot --quiet "
                       "--methods brute,octree,octree-point,kd,kd-point,bsp,bsp-balanced --spheres ";
    args += std::to_string(spheres);
    args += " --frames ";
    args += std::to_string(frames);
    args += " --out ";
    args += quote(dir / "s");
    const auto r = run_tethash(args);
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(std::filesystem::exists(dir / "s" / "spheres.json"));
    const Table t = Table::read_csv((dir / "s" / "spheres.csv").string());
    ASSERT_EQ(t.rows.size(), static_cast<std::size_t>(frames * (1 + 6 * 2)));

    std::map<int, std::pair<std::string, std::string>> brute; // frame -> (collisions, hash)
    std::map<std::string, long long> tests_per_method;
    long long collisions_total = 0;
    std::set<std::string> methods;
    for (const auto& row : t.rows) {
        const std::string method = cell(t, row, "method");
        const int frame = std::stoi(cell(t, row, "frame"));
        const long long n = std::stoll(cell(t, row, "spheres"));
        EXPECT_EQ(n, std::min(frame + 1, spheres));
        EXPECT_GE(std::stod(cell(t, row, "time_ms")), 0.0);
        const long long tests = std::stoll(cell(t, row, "tests"));
        methods.insert(method + "/" + cell(t, row, "depth"));
        tests_per_method[method + "/" + cell(t, row, "depth")] += tests;
        if (method == "brute") {
            EXPECT_EQ(tests, n * (n - 1) / 2) << "frame " << frame;
            brute[frame] = {cell(t, row, "collisions"), cell(t, row, "collision_hash")};
            collisions_total += std::stoll(cell(t, row, "collisions"));
        } else {
            ASSERT_TRUE(brute.count(frame)) << "brute's row comes first in each frame";
            EXPECT_EQ(cell(t, row, "collisions"), brute[frame].first) << method << " frame " << frame;
            EXPECT_EQ(cell(t, row, "collision_hash"), brute[frame].second) << method << " frame " << frame;
            EXPECT_LE(tests, n * (n - 1) / 2) << method << " frame " << frame; // each pair once at most
            EXPECT_GE(std::stoll(cell(t, row, "nodes")), 1);
            EXPECT_LE(std::stoi(cell(t, row, "tree_depth")), std::stoi(cell(t, row, "depth")));
        }
    }
    EXPECT_EQ(methods.size(), 13U);
    EXPECT_GT(collisions_total, 0) << "the spheres never touched: the experiment tests nothing";
    for (const auto& [m, tests] : tests_per_method)
        if (m != "brute/0") {
            EXPECT_LT(tests, tests_per_method["brute/0"]) << m << " tests no fewer pairs than brute";
        }
}

TEST(CliSpheres, SameSeedSameSimulation)
{
    const auto dir = test::temp_dir();
    std::string hashes[2];
    for (int k = 0; k < 2; ++k) {
        const auto out = dir / (k == 0 ? "s0" : "s1");
        std::string args = "study spheres --spheres 30 --frames 40 --radius 0.1 --depths 3 --no-plot --quiet "
                           "--seed 7 --methods ";
        args += k == 0 ? "brute" : "kd-point,brute";
        args += " --out ";
        args += quote(out);
        const auto r = run_tethash(args);
        ASSERT_EQ(r.status, 0) << r.err;
        const Table t = Table::read_csv((out / "spheres.csv").string());
        for (const auto& row : t.rows)
            if (cell(t, row, "method") == "brute") hashes[k] += cell(t, row, "collision_hash");
    }
    EXPECT_EQ(hashes[0], hashes[1]) << "another method in the run changed the simulation";
}

TEST(CliSpheres, BadOptionsExit2)
{
    const auto dir = test::temp_dir();
    const std::string out = " --out " + quote(dir / "bad");
    expect_refused(run_tethash("study spheres --frames 0" + out), {"--frames"});
    expect_refused(run_tethash("study spheres --spheres -3" + out), {"--spheres"});
    expect_refused(run_tethash("study spheres --methods brute,quadtree" + out), {"--methods", "quadtree"});
    expect_refused(run_tethash("study spheres --methods kd,kd" + out), {"--methods", "twice"});
    expect_refused(run_tethash("study spheres --depths 3,31" + out), {"--depths", "31"});
    expect_refused(run_tethash("study spheres --radius 0.5" + out), {"--radius"});
    expect_refused(run_tethash("study spheres --leaf-size 0" + out), {"--leaf-size"});
    expect_refused(run_tethash("study spheres --frames x" + out), {"--frames"});
    expect_refused(run_tethash("study spheres extra" + out), {"extra"});
    expect_refused(run_tethash("study cell-size --spheres 10" + out), {"--spheres", "only for"});
    EXPECT_FALSE(std::filesystem::exists(dir / "bad" / "spheres.csv"));
}

} // namespace
} // namespace tethash
