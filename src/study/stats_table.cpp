// The detector's statistics as one table (stats_table.hpp).
#include "tethash/study/stats_table.hpp"

#include "tethash/study/table.hpp"

#include <tuple>
#include <utility>

namespace tethash::study {

namespace {

/// BspStats' fields in declaration order (tests/test_study_stats_table.cpp checks the count), each with its key.
constexpr auto k_bsp_fields =
    std::make_tuple(std::pair{"triangles", &BspStats::triangles}, std::pair{"planes", &BspStats::planes},
                    std::pair{"nodes", &BspStats::nodes}, std::pair{"leaves_in", &BspStats::leaves_in},
                    std::pair{"leaves_out", &BspStats::leaves_out}, std::pair{"depth", &BspStats::depth},
                    std::pair{"mean_depth", &BspStats::mean_depth}, std::pair{"splits", &BspStats::splits},
                    std::pair{"bytes", &BspStats::bytes}, std::pair{"flipped", &BspStats::flipped},
                    std::pair{"build_ms", &BspStats::build_ms});

} // namespace

std::string stat_text(const StatField& field, const DetectStats& stats)
{
    const double v = field.get(stats);
    if (field.kind == StatKind::count) return std::to_string(static_cast<long long>(v));
    return fmt_double(v);
}

void write_stat(JsonWriter& j, const StatField& field, const DetectStats& stats)
{
    const double v = field.get(stats);
    j.key(field.name);
    if (field.kind == StatKind::count)
        j.value(static_cast<long long>(v));
    else
        j.value(v);
}

void write_stats(JsonWriter& j, const BspStats& stats)
{
    std::apply([&](const auto&... field) { (j.member(field.first, stats.*field.second), ...); }, k_bsp_fields);
}

} // namespace tethash::study
