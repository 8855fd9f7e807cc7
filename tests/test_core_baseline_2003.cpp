// Tests of tethash_bench's baseline, the plain 2003 algorithm (tools/bench/baseline_2003.hpp): like every detection
// method it must find the oracle's contacts, or the benchmark would compare the times of different answers.
#include "core_scenes.hpp"

#include "tethash/oracle.hpp"

#include "baseline_2003.hpp"

#include <gtest/gtest.h>

#include <utility>
#include <vector>

using namespace tethash;

namespace {

TetMesh mesh_of(const test::Scene& s)
{
    TetMesh m;
    m.positions = s.positions;
    m.tets = s.tets;
    m.vertex_object = s.vertex_object;
    m.tet_object = s.tet_object;
    return m;
}

} // namespace

TEST(Baseline2003, FindsTheOraclesContactsOnRandomScenesAtEveryCellSize)
{
    for (std::uint32_t seed = 1; seed <= 5; ++seed) {
        const test::Scene s = test::random_scene(seed, 4, 3, 0.2);
        const TetMesh m = mesh_of(s);
        // The baseline has no object rules: every object collides with itself and the others, the oracle's default.
        const std::vector<Contact> want = brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object);
        ASSERT_FALSE(want.empty()) << "seed " << seed;
        bench::Baseline2003 baseline; // kept across runs: the buckets are stamped with the run, not cleared
        std::vector<std::pair<Index, Index>> got;
        for (double cell : {0.05, 0.2, 0.6, 2.0}) {
            baseline.run(m, cell, got);
            EXPECT_TRUE(bench::same_pairs(got, want))
                << "seed " << seed << ", cell " << cell << ": " << got.size() << " pairs, oracle " << want.size();
        }
    }
}

TEST(Baseline2003, SamePairsTellsAMissedAnExtraAndAMovedPair)
{
    const test::Scene s = test::random_scene(7, 3, 3, 0.2);
    const std::vector<Contact> want = brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object);
    ASSERT_GE(want.size(), 2u);
    std::vector<std::pair<Index, Index>> pairs;
    for (auto it = want.rbegin(); it != want.rend(); ++it) // any order
        pairs.emplace_back(it->vertex, it->tet);
    EXPECT_TRUE(bench::same_pairs(pairs, want));
    auto missed = pairs;
    missed.pop_back();
    EXPECT_FALSE(bench::same_pairs(missed, want));
    auto extra = pairs;
    extra.emplace_back(0, 0);
    EXPECT_FALSE(bench::same_pairs(extra, want));
    auto moved = pairs;
    moved.front().second += 1;
    EXPECT_FALSE(bench::same_pairs(moved, want));
}
