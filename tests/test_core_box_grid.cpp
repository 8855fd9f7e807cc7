// The grid of boxes (src/core/hash/box_grid.hpp): its box filter kernels agree with the direct test and follow
// TETHASH_SIMD; a query meets every box whose box meets its own, once, on random boxes of every size (one cell to
// many, cells shared in buckets), as the direct test over all boxes does.
// The team build splits work by the OpenMP team (src/core/team.hpp): this file sees the team as the library does.
#if defined(_OPENMP) && !defined(TETHASH_HAVE_OPENMP)
#define TETHASH_HAVE_OPENMP 1
#endif
#include "../src/core/hash/box_grid.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

using namespace tethash;

TEST(CoreBoxGrid, FilterKernelsAgree)
{
    // Random buckets of 0-40 boxes (touching the query exactly, NaN corners, every tail length of the eight-wide
    // kernel, boxes that meet the query right after the range): each kernel gives the entries of the range whose
    // box meets the query's, in order, as the direct test does.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.0f, 0.6f);
    const auto kernels = detail::box_filters();
    ASSERT_FALSE(kernels.empty());
    int met = 0, missed = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const int n = static_cast<int>(rng() % 41), begin = static_cast<int>(rng() % 5);
        std::vector<float> col[6];
        for (auto& c : col)
            c.assign(static_cast<size_t>(begin + n + 8), 0.0f);
        float q[6];
        for (int k = 0; k < 3; ++k) {
            q[k] = u(rng);
            q[3 + k] = q[k] + size(rng);
        }
        // Boxes before and after the range too (a bucket's neighbours in the grid's columns), the ones after
        // all meeting the query.
        for (int e = 0; e < begin + n + 8; ++e)
            for (int k = 0; k < 3; ++k) {
                if (e >= begin + n) {
                    col[k][static_cast<size_t>(e)] = q[k];
                    col[3 + k][static_cast<size_t>(e)] = q[3 + k];
                    continue;
                }
                const float lo = u(rng);
                col[k][static_cast<size_t>(e)] = rng() % 16 == 0 ? q[3 + k] : lo; // touching the query's hi
                col[3 + k][static_cast<size_t>(e)] = rng() % 16 == 0 ? q[k] : lo + size(rng);
                if (rng() % 64 == 0) col[k][static_cast<size_t>(e)] = std::numeric_limits<float>::quiet_NaN();
            }
        std::vector<std::int32_t> expected;
        for (int e = begin; e < begin + n; ++e) {
            bool miss = false;
            for (int k = 0; k < 3; ++k)
                miss = miss || q[3 + k] < col[k][static_cast<size_t>(e)] || q[k] > col[3 + k][static_cast<size_t>(e)];
            if (!miss) expected.push_back(e);
        }
        met += static_cast<int>(expected.size());
        missed += n - static_cast<int>(expected.size());
        const float* const columns[6] = {col[0].data(), col[1].data(), col[2].data(),
                                         col[3].data(), col[4].data(), col[5].data()};
        for (const auto& [name, filter] : kernels) {
            std::vector<std::int32_t> hits(static_cast<size_t>(n) + 1, -1);
            const std::int32_t count = filter(columns, begin, begin + n, q, hits.data());
            hits.resize(static_cast<size_t>(count));
            EXPECT_EQ(hits, expected) << name << " trial " << trial;
        }
    }
    EXPECT_GT(met, 100);
    EXPECT_GT(missed, 100);
}

TEST(CoreBoxGrid, FilterFollowsTethashSimd)
{
    test::expect_kernel_follows_tethash_simd(detail::box_filter_name());
}

TEST(CoreBoxGrid, QueryMeetsEachMeetingBoxOnce)
{
    // 300 boxes from a point to several cells wide in a table of 64 buckets (many cells share a bucket), queried
    // by boxes as varied; with stamps always (each box once) and with repeats harmless (each box at least once).
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> where(-3.0, 3.0), size(0.0, 1.5);
    std::vector<std::array<double, 6>> boxes(300);
    for (auto& b : boxes)
        for (int k = 0; k < 3; ++k) {
            b[static_cast<size_t>(k)] = where(rng);
            b[static_cast<size_t>(3 + k)] = b[static_cast<size_t>(k)] + (rng() % 4 == 0 ? 0.0 : size(rng));
        }
    detail::BoxGrid grid;
    grid.build(0.5, 64, boxes.size(), [&](std::int32_t i, double lo[3], double hi[3]) {
        std::copy(boxes[static_cast<size_t>(i)].begin(), boxes[static_cast<size_t>(i)].begin() + 3, lo);
        std::copy(boxes[static_cast<size_t>(i)].begin() + 3, boxes[static_cast<size_t>(i)].end(), hi);
    });
    std::vector<std::int32_t> stamp(boxes.size(), -1), hits;
    int met = 0;
    for (std::int32_t query = 0; query < 400; ++query) {
        double lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
            lo[k] = where(rng);
            hi[k] = lo[k] + (query % 3 == 0 ? 0.0 : size(rng));
        }
        std::vector<std::int32_t> want;
        for (size_t i = 0; i < boxes.size(); ++i) {
            const auto& b = boxes[i];
            if (lo[0] <= b[3] && lo[1] <= b[4] && lo[2] <= b[5] && hi[0] >= b[0] && hi[1] >= b[1] && hi[2] >= b[2])
                want.push_back(static_cast<std::int32_t>(i));
        }
        met += static_cast<int>(want.size());
        for (const bool repeats_harmless : {false, true}) {
            std::vector<std::int32_t> got;
            const std::int32_t tag = 2 * query + (repeats_harmless ? 1 : 0);
            grid.query(lo, hi, stamp.data(), tag, hits, repeats_harmless, [&](std::int32_t i) {
                const auto& b = boxes[static_cast<size_t>(i)];
                // The float filter keeps a little more than the exact test: the caller's test decides.
                if (lo[0] <= b[3] && lo[1] <= b[4] && lo[2] <= b[5] && hi[0] >= b[0] && hi[1] >= b[1] && hi[2] >= b[2])
                    got.push_back(i);
            });
            std::sort(got.begin(), got.end());
            if (!repeats_harmless) {
                EXPECT_EQ(got, want) << "query " << query;
            } else {
                got.erase(std::unique(got.begin(), got.end()), got.end());
                EXPECT_EQ(got, want) << "query " << query << " (repeats harmless)";
            }
        }
    }
    EXPECT_GT(met, 200);
}

TEST(CoreBoxGrid, QueryAboveMeetsTheHigherBoxesOnly)
{
    // Boxes of the grid querying it with query_above(their own index): each box meets the boxes above it that meet
    // its box, once, and never itself or a box below (each pair once, from its lower box).
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> where(-2.0, 2.0), size(0.0, 1.2);
    std::vector<std::array<double, 6>> boxes(250);
    for (auto& b : boxes)
        for (int k = 0; k < 3; ++k) {
            b[static_cast<size_t>(k)] = where(rng);
            b[static_cast<size_t>(3 + k)] = b[static_cast<size_t>(k)] + (rng() % 4 == 0 ? 0.0 : size(rng));
        }
    const auto meet = [](const std::array<double, 6>& a, const std::array<double, 6>& b) {
        return a[0] <= b[3] && a[1] <= b[4] && a[2] <= b[5] && b[0] <= a[3] && b[1] <= a[4] && b[2] <= a[5];
    };
    detail::BoxGrid grid;
    grid.build(0.5, 64, boxes.size(), [&](std::int32_t i, double lo[3], double hi[3]) {
        std::copy(boxes[static_cast<size_t>(i)].begin(), boxes[static_cast<size_t>(i)].begin() + 3, lo);
        std::copy(boxes[static_cast<size_t>(i)].begin() + 3, boxes[static_cast<size_t>(i)].end(), hi);
    });
    std::vector<std::int32_t> stamp(boxes.size(), -1), hits;
    int pairs = 0;
    for (std::int32_t q = 0; q < static_cast<std::int32_t>(boxes.size()); ++q) {
        const auto& b = boxes[static_cast<size_t>(q)];
        std::vector<std::int32_t> want, got;
        for (std::int32_t i = q + 1; i < static_cast<std::int32_t>(boxes.size()); ++i)
            if (meet(b, boxes[static_cast<size_t>(i)])) want.push_back(i);
        grid.query_above(q, b.data(), b.data() + 3, stamp.data(), q, hits, false, [&](std::int32_t i) {
            EXPECT_GT(i, q) << "query " << q;
            if (meet(b, boxes[static_cast<size_t>(i)])) got.push_back(i);
        });
        std::sort(got.begin(), got.end());
        EXPECT_EQ(got, want) << "query " << q;
        pairs += static_cast<int>(want.size());
    }
    EXPECT_GT(pairs, 100);
}

TEST(CoreBoxGrid, TeamBuildIsTheGridOfOneThread)
{
    // The grid built by teams of 1, 2 and 3 threads (each its part of the boxes, counts, cursors, scatter) visits
    // every query's boxes in the same order as the grid one thread builds alone: the same buckets holding the same
    // boxes in the same order. Also with fewer boxes than threads, and none; and grids built alone by each thread of
    // a region (a caller inside someone else's team) are that grid too.
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> where(-3.0, 3.0), size(0.0, 1.5);
    for (const std::size_t count : {std::size_t{500}, std::size_t{2}, std::size_t{0}}) {
        std::vector<std::array<double, 6>> boxes(count);
        for (auto& b : boxes)
            for (int k = 0; k < 3; ++k) {
                b[static_cast<size_t>(k)] = where(rng);
                b[static_cast<size_t>(3 + k)] = b[static_cast<size_t>(k)] + (rng() % 4 == 0 ? 0.0 : size(rng));
            }
        const auto box_of = [&](std::int32_t i, double lo[3], double hi[3]) {
            for (int k = 0; k < 3; ++k) {
                lo[k] = boxes[static_cast<size_t>(i)][static_cast<size_t>(k)];
                hi[k] = boxes[static_cast<size_t>(i)][static_cast<size_t>(3 + k)];
            }
        };
        detail::BoxGrid serial;
        serial.build(0.5, 128, boxes.size(), box_of);
        detail::BoxGrid alone[2];
#pragma omp parallel num_threads(2)
        alone[detail::team_rank() % 2].build(0.5, 128, boxes.size(), box_of);
        for (const int threads : {1, 2, 3}) {
            detail::BoxGrid team;
            for (int round = 0; round < 2; ++round) { // a second build reuses the parts' buffers
                int team_size = 1;
#pragma omp parallel num_threads(threads)
                {
                    team.build(0.5, 128, boxes.size(), box_of, detail::team_rank(), detail::team_size());
#pragma omp single
                    team_size = detail::team_size();
                }
#ifdef _OPENMP
                EXPECT_EQ(team_size, threads);
#endif
                std::vector<std::int32_t> stamp_a(boxes.size() + 1, -1), stamp_b(boxes.size() + 1, -1), hits;
                int visits = 0;
                for (std::int32_t query = 0; query < 200; ++query) {
                    double lo[3], hi[3];
                    for (int k = 0; k < 3; ++k) {
                        lo[k] = where(rng);
                        hi[k] = lo[k] + size(rng);
                    }
                    std::vector<std::int32_t> a, b;
                    serial.query(lo, hi, stamp_a.data(), query, hits, false, [&](std::int32_t i) { a.push_back(i); });
                    team.query(lo, hi, stamp_b.data(), query, hits, false, [&](std::int32_t i) { b.push_back(i); });
                    for (const detail::BoxGrid& own : alone) {
                        std::vector<std::int32_t> c, stamp_c(boxes.size() + 1, -1);
                        own.query(lo, hi, stamp_c.data(), query, hits, false, [&](std::int32_t i) { c.push_back(i); });
                        EXPECT_EQ(a, c) << count << " boxes, a grid built alone in a region, query " << query;
                    }
                    EXPECT_EQ(a, b) << count << " boxes, " << threads << " threads, round " << round << ", query "
                                    << query;
                    visits += static_cast<int>(a.size());
                }
                if (count > 100) {
                    EXPECT_GT(visits, 500);
                }
            }
        }
    }
}
