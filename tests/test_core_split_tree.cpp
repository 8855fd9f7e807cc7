// The splitting-plane tree (octree, k-d, BSP rules): every query equals a brute-force scan of closed box
// overlaps, each item once; leaves cover every item; depth and leaf-size limits; statistics; bad arguments;
// concurrent queries.
#include "../src/core/broad_phase/split_tree.hpp"
#include "tethash/error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

using namespace tethash;

namespace {

const std::vector<SplitRule> kRules{SplitRule::region_octree, SplitRule::point_octree, SplitRule::region_kd,
                                    SplitRule::point_kd,      SplitRule::bsp,          SplitRule::bsp_balanced};

SplitBox point_box(double x, double y, double z)
{
    SplitBox b;
    b.lo = b.hi = {x, y, z};
    return b;
}

bool overlap(const SplitBox& a, const SplitBox& b)
{
    for (std::size_t k = 0; k < 3; ++k)
        if (a.lo[k] > b.hi[k] || a.hi[k] < b.lo[k]) return false;
    return true;
}

std::vector<std::uint32_t> brute(const std::vector<SplitBox>& items, const SplitBox& q)
{
    std::vector<std::uint32_t> r;
    for (std::size_t i = 0; i < items.size(); ++i)
        if (overlap(items[i], q)) r.push_back(static_cast<std::uint32_t>(i));
    return r;
}

std::vector<SplitBox> random_points(std::mt19937& rng, int n, bool grid)
{
    std::uniform_real_distribution<double> u(-1, 1);
    std::uniform_int_distribution<int> g(-4, 4);
    std::vector<SplitBox> v;
    for (int i = 0; i < n; ++i) {
        if (grid) // on a coarse lattice: many points exactly on the mid- and median planes, many duplicates
            v.push_back(point_box(g(rng) * 0.25, g(rng) * 0.25, g(rng) * 0.25));
        else
            v.push_back(point_box(u(rng), u(rng), u(rng)));
    }
    return v;
}

std::vector<SplitBox> random_boxes(std::mt19937& rng, int n, double size)
{
    std::uniform_real_distribution<double> u(-1, 1), s(0, size);
    std::vector<SplitBox> v;
    for (int i = 0; i < n; ++i) {
        SplitBox b;
        for (std::size_t k = 0; k < 3; ++k) {
            b.lo[k] = u(rng);
            b.hi[k] = b.lo[k] + s(rng);
        }
        v.push_back(b);
    }
    return v;
}

/// Queries: random boxes, degenerate (point) queries on items, queries touching item faces exactly.
std::vector<SplitBox> queries_for(std::mt19937& rng, const std::vector<SplitBox>& items, int count)
{
    auto q = random_boxes(rng, count, 0.6);
    for (std::size_t i = 0; i < items.size() && i < 40; ++i) {
        q.push_back(point_box(items[i].lo[0], items[i].lo[1], items[i].lo[2]));
        SplitBox t; // touches item i on its upper x face only
        t.lo = {items[i].hi[0], items[i].lo[1] - 0.1, items[i].lo[2] - 0.1};
        t.hi = {items[i].hi[0] + 0.2, items[i].hi[1], items[i].hi[2]};
        q.push_back(t);
    }
    return q;
}

/// Query results equal brute force exactly, each item once, with and without a scratch.
void check_queries(const SplitTree& tree, const std::vector<SplitBox>& items, const std::vector<SplitBox>& queries,
                   const std::string& what)
{
    SplitTreeScratch scratch;
    std::vector<std::uint32_t> got, got2;
    for (std::size_t k = 0; k < queries.size(); ++k) {
        const auto expect = brute(items, queries[k]);
        got.clear();
        tree.query(queries[k], got, scratch);
        auto sorted = got;
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end())
            << what << " query " << k << ": an item twice";
        ASSERT_EQ(sorted, expect) << what << " query " << k;
        got2.assign(3, 7); // appends after what is there
        tree.query(queries[k], got2);
        ASSERT_EQ(got2.size(), expect.size() + 3) << what << " query " << k;
        std::vector<std::uint32_t> tail(got2.begin() + 3, got2.end());
        std::sort(tail.begin(), tail.end());
        ASSERT_EQ(tail, expect) << what << " query " << k;
    }
}

/// Leaves cover every item; limits and statistics.
void check_structure(const SplitTree& tree, std::size_t n, const SplitTreeParams& p, const std::string& what)
{
    const auto st = tree.stats();
    const int limit = p.max_depth < 0 ? default_split_depth(p.rule) : p.max_depth;
    std::vector<int> seen(n, 0);
    std::int64_t stored = 0;
    int deepest = 0;
    for (std::size_t k = 0; k < tree.leaf_count(); ++k) {
        const auto ids = tree.leaf_items(k);
        EXPECT_LE(tree.leaf_depth(k), limit) << what;
        deepest = std::max(deepest, tree.leaf_depth(k));
        EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end())) << what;
        for (auto id : ids) {
            ASSERT_LT(id, n) << what;
            ++seen[id];
        }
        stored += static_cast<std::int64_t>(ids.size());
    }
    bool dup = false;
    for (std::size_t i = 0; i < n; ++i) {
        EXPECT_GE(seen[i], 1) << what << ": item " << i << " in no leaf";
        dup = dup || seen[i] > 1;
    }
    EXPECT_EQ(dup, tree.stores_duplicates()) << what;
    EXPECT_EQ(st.items, static_cast<std::int64_t>(n)) << what;
    EXPECT_EQ(st.items_stored, stored) << what;
    EXPECT_EQ(st.leaves, static_cast<std::int64_t>(tree.leaf_count())) << what;
    EXPECT_EQ(st.max_depth, deepest) << what;
    EXPECT_LE(st.max_depth, limit) << what;
    EXPECT_GE(st.nodes, st.leaves) << what;
    EXPECT_GT(st.bytes, 0) << what;
    // Every inner node has 2 or 8 children: nodes - 1 = inner x (2 or 8).
    const std::int64_t branching = p.rule == SplitRule::region_octree || p.rule == SplitRule::point_octree ? 8 : 2;
    EXPECT_EQ((st.nodes - 1) % branching, 0) << what;
    EXPECT_EQ(st.nodes - st.leaves, (st.nodes - 1) / branching) << what;
}

void run_case(const std::vector<SplitBox>& items, std::mt19937& rng, const std::string& name, bool points)
{
    const auto queries = queries_for(rng, items, 60);
    for (SplitRule r : kRules) {
        for (int depth : {-1, 2, 7}) {
            for (int leaf : {1, 4}) {
                const SplitTreeParams p{r, depth, leaf};
                SplitTree tree(p);
                tree.build(items);
                const std::string what = name + " " + std::string(split_rule_name(r)) +
                                         " depth=" + std::to_string(depth) + " leaf=" + std::to_string(leaf);
                check_structure(tree, items.size(), p, what);
                if (points) {
                    EXPECT_FALSE(tree.stores_duplicates()) << what << ": a point stored twice";
                }
                check_queries(tree, items, queries, what);
            }
        }
    }
}

} // namespace

TEST(SplitTree, RandomPoints)
{
    std::mt19937 rng(11);
    run_case(random_points(rng, 500, false), rng, "random points", true);
}

TEST(SplitTree, LatticePointsOnPlanesAndDuplicates)
{
    std::mt19937 rng(12);
    run_case(random_points(rng, 400, true), rng, "lattice points", true);
}

TEST(SplitTree, RandomBoxes)
{
    std::mt19937 rng(13);
    run_case(random_boxes(rng, 300, 0.3), rng, "boxes", false);
}

TEST(SplitTree, MixedPointsAndBoxes)
{
    std::mt19937 rng(14);
    auto items = random_points(rng, 150, true);
    const auto b = random_boxes(rng, 150, 0.5);
    items.insert(items.end(), b.begin(), b.end());
    run_case(items, rng, "mixed", false);
}

TEST(SplitTree, FarFromOriginAndTinyScale)
{
    // Rounding of general planes: coordinates of 1e6 with spacing 1e-3, and of 1e-9.
    std::mt19937 rng(15);
    for (double scale : {1e-9, 1.0}) {
        for (double shift : {0.0, 1e6}) {
            auto items = random_points(rng, 200, true);
            for (auto& it : items)
                for (std::size_t k = 0; k < 3; ++k) {
                    it.lo[k] = it.lo[k] * scale * 1e-3 + shift;
                    it.hi[k] = it.lo[k];
                }
            std::vector<SplitBox> queries;
            for (const auto& it : items) { // point queries exactly on the items
                queries.push_back(it);
                if (queries.size() >= 80) break;
            }
            for (SplitRule r : kRules) {
                SplitTree tree({r, 8, 2});
                tree.build(items);
                check_queries(tree, items, queries, std::string(split_rule_name(r)) + " shifted");
            }
        }
    }
}

TEST(SplitTree, AllEqualEmptyAndOne)
{
    std::mt19937 rng(16);
    const std::vector<SplitBox> same(100, point_box(0.5, -0.25, 0.125));
    const std::vector<SplitBox> empty;
    const std::vector<SplitBox> one{point_box(0.1, 0.2, 0.3)};
    for (SplitRule r : kRules) {
        const SplitTreeParams p{r, -1, 8};
        SplitTree tree(p);
        tree.build(same);
        check_structure(tree, same.size(), p, "all equal");
        check_queries(tree, same, queries_for(rng, same, 10), "all equal");
        EXPECT_FALSE(tree.stores_duplicates());
        tree.build(empty);
        EXPECT_EQ(tree.leaf_count(), 1U);
        EXPECT_EQ(tree.stats().items_stored, 0);
        std::vector<std::uint32_t> out;
        tree.query(point_box(0, 0, 0), out);
        EXPECT_TRUE(out.empty());
        tree.build(one);
        check_queries(tree, one, queries_for(rng, one, 10), "one");
        tree.query(one[0], out);
        EXPECT_EQ(out, std::vector<std::uint32_t>{0});
    }
}

TEST(SplitTree, LimitsRespected)
{
    std::mt19937 rng(17);
    const auto items = random_points(rng, 2000, false);
    for (SplitRule r : kRules) {
        for (int depth : {0, 1, 3, 7}) {
            const SplitTreeParams p{r, depth, 8};
            SplitTree tree(p);
            tree.build(items);
            EXPECT_LE(tree.stats().max_depth, depth);
            for (std::size_t k = 0; k < tree.leaf_count(); ++k)
                if (tree.leaf_depth(k) < depth) { // distinct random points: every split separates
                    EXPECT_LE(tree.leaf_items(k).size(), 8U) << split_rule_name(r) << " depth " << depth;
                }
        }
        // Median rules at a large depth: every leaf at most leaf_size (distinct points).
        if (r != SplitRule::region_octree && r != SplitRule::region_kd) {
            SplitTree tree({r, 30, 8});
            tree.build(items);
            for (std::size_t k = 0; k < tree.leaf_count(); ++k)
                EXPECT_LE(tree.leaf_items(k).size(), 8U) << split_rule_name(r);
        }
    }
    // Depth 0: a single leaf with everything.
    SplitTree root_only({SplitRule::point_kd, 0, 1});
    root_only.build(items);
    EXPECT_EQ(root_only.leaf_count(), 1U);
    EXPECT_EQ(root_only.stats().nodes, 1);
}

TEST(SplitTree, MedianSplitsAreBalanced)
{
    // The point k-d tree halves its points per level: about n / 2^depth per leaf.
    std::mt19937 rng(18);
    const auto items = random_points(rng, 1024, false);
    SplitTree tree({SplitRule::point_kd, 4, 1});
    tree.build(items);
    EXPECT_EQ(tree.leaf_count(), 16U);
    for (std::size_t k = 0; k < tree.leaf_count(); ++k)
        EXPECT_EQ(tree.leaf_items(k).size(), 64U);
}

TEST(SplitTree, RebuildReusesAndStaysExact)
{
    std::mt19937 rng(19);
    SplitTree tree({SplitRule::bsp, 7, 4});
    for (int round = 0; round < 5; ++round) {
        const auto items = random_boxes(rng, 200 + 10 * round, 0.2);
        tree.build(items);
        check_queries(tree, items, queries_for(rng, items, 20), "rebuild");
    }
}

TEST(SplitTree, NamesAndBadArguments)
{
    for (SplitRule r : kRules)
        EXPECT_EQ(parse_split_rule(split_rule_name(r)), r);
    EXPECT_FALSE(parse_split_rule("quadtree").has_value());
    EXPECT_THROW(SplitTree({SplitRule::bsp, 31, 8}), Error);
    EXPECT_THROW(SplitTree({SplitRule::bsp, -2, 8}), Error);
    EXPECT_THROW(SplitTree({SplitRule::bsp, 5, 0}), Error);
    SplitTree tree;
    std::vector<SplitBox> bad{point_box(0, 0, 0), point_box(0, std::nan(""), 0)};
    try {
        tree.build(bad);
        FAIL() << "no error for a NaN";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("item 1"), std::string::npos) << e.what();
    }
    SplitBox inverted;
    inverted.lo = {1, 0, 0};
    inverted.hi = {0, 1, 1};
    EXPECT_THROW(tree.build(std::vector<SplitBox>{inverted}), Error);
}

TEST(SplitTree, ConcurrentQueriesEqualSerial)
{
    // query is const: several threads on one tree, each with its own scratch, give the serial answers.
    std::mt19937 rng(20);
    const auto items = random_boxes(rng, 400, 0.3); // straddlers: the scratch path
    const auto queries = random_boxes(rng, 400, 0.4);
    for (SplitRule r : kRules) {
        SplitTree tree({r, 6, 2});
        tree.build(items);
        ASSERT_TRUE(tree.stores_duplicates()) << split_rule_name(r);
        std::vector<std::vector<std::uint32_t>> serial(queries.size()), parallel(queries.size());
        SplitTreeScratch s;
        for (std::size_t k = 0; k < queries.size(); ++k)
            tree.query(queries[k], serial[k], s);
        const auto count = static_cast<std::int64_t>(queries.size());
#pragma omp parallel num_threads(4)
        {
            SplitTreeScratch mine;
#pragma omp for schedule(dynamic, 7)
            for (std::int64_t k = 0; k < count; ++k)
                tree.query(queries[static_cast<std::size_t>(k)], parallel[static_cast<std::size_t>(k)], mine);
        }
        EXPECT_EQ(serial, parallel) << split_rule_name(r);
    }
}
