// The table of detector statistics (study/stats_table.hpp): every field of DetectStats exactly once;
// the BSP tree's statistics as JSON.
#include "tethash/study/stats_table.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <utility>

namespace tethash {
namespace {

/// Converts to any field type: brace-initialising an aggregate with N of these compiles iff it has ≥ N fields.
struct AnyField {
    template <class T> operator T() const { return T{}; }
};

template <class T, std::size_t... I>
constexpr auto braces(std::index_sequence<I...>, int) -> decltype(T{(void(I), AnyField{})...}, true)
{
    return true;
}
template <class T, std::size_t... I> constexpr bool braces(std::index_sequence<I...>, long)
{
    return false;
}

template <class T, std::size_t N = 0> constexpr std::size_t field_count()
{
    if constexpr (!braces<T>(std::make_index_sequence<N + 1>{}, 0))
        return N;
    else
        return field_count<T, N + 1>();
}

TEST(StudyStatsTable, EveryFieldOfDetectStatsAppearsOnce)
{
    constexpr std::size_t fields = field_count<DetectStats>();
    static_assert(fields == 29, "DetectStats changed: add the new field to study/stats_table.hpp (and here)");
    // Fields 1..29 in declaration order; each accessor of a member must read a different one.
    const DetectStats s{1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 14, 15,
                        16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29};
    std::set<double> seen;
    std::set<std::string> names;
    std::size_t members = 0;
    for (const study::StatField& f : study::k_detect_stats) {
        EXPECT_TRUE(names.insert(f.name).second) << "twice: " << f.name;
        if (f.derived) continue;
        ++members;
        EXPECT_TRUE(seen.insert(f.get(s)).second) << f.name << " reads a field another entry reads";
    }
    EXPECT_EQ(members, fields);
    EXPECT_EQ(seen.size(), fields);
    EXPECT_EQ(*seen.begin(), 1);
    EXPECT_EQ(*seen.rbegin(), static_cast<double>(fields));
}

TEST(StudyStatsTable, NamesKindsAndText)
{
    DetectStats s;
    s.cell_size = 0.125;
    s.table_size = 4096;
    s.hash_collisions = 1;
    s.entries_scanned = 4;
    s.ms_tets = 1.5;
    for (const study::StatField& f : study::k_detect_stats) {
        if (std::string(f.name).rfind("ms_", 0) == 0) {
            EXPECT_EQ(f.kind, study::StatKind::timing) << f.name;
            EXPECT_STREQ(f.unit, "ms");
        } else {
            EXPECT_NE(f.kind, study::StatKind::timing) << f.name;
        }
        if (f.use & study::in_bench) {
            EXPECT_NE(f.bench_label, nullptr) << f.name;
        }
        const std::map<std::string, std::string> want = {
            {"cell_size", "0.125"}, {"table_size", "4096"}, {"collision_rate", "0.25"}, {"ms_tets", "1.5"}};
        if (const auto it = want.find(f.name); it != want.end()) {
            EXPECT_EQ(study::stat_text(f, s), it->second);
        }
    }
    study::JsonWriter j;
    j.begin_object(study::JsonWriter::inline_layout);
    for (const study::StatField& f : study::k_detect_stats)
        if (std::string(f.name) == "table_size" || std::string(f.name) == "cell_size") study::write_stat(j, f, s);
    j.end_object();
    EXPECT_EQ(j.str(), R"({"cell_size": 0.125, "table_size": 4096})");
}

TEST(StudyStatsTable, EveryFieldOfBspStatsWrittenInOrder)
{
    static_assert(field_count<BspStats>() == 11, "BspStats changed: add the new field to study/stats_table.cpp");
    const BspStats s{1, 2, 3, 4, 5, 6, 7.5, 8, 9, true, 11.25};
    study::JsonWriter j;
    j.begin_object(study::JsonWriter::inline_layout);
    study::write_stats(j, s);
    j.end_object();
    EXPECT_EQ(j.str(), R"({"triangles": 1, "planes": 2, "nodes": 3, "leaves_in": 4, "leaves_out": 5, "depth": 6, )"
                       R"("mean_depth": 7.5, "splits": 8, "bytes": 9, "flipped": true, "build_ms": 11.25})");
}

} // namespace
} // namespace tethash
