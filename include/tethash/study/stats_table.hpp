#pragma once
/// \file study/stats_table.hpp
/// The detector's statistics (detect.hpp: DetectStats) as one table: each field's name (the study's CSV column,
/// the key of `tethash detect --stats`), unit, kind and where it is shown. The study, the `detect` command and
/// tethash_bench list the statistics from here, in this order. The BSP tree's statistics (bsp.hpp: BspStats) are
/// written to JSON from a field list too (`tethash info --json` on a surface).

#include "tethash/bsp.hpp"
#include "tethash/detect.hpp"
#include "tethash/study/json.hpp"

#include <array>
#include <string>

namespace tethash::study {

enum class StatKind {
    count,  ///< an integer (the field is an int or std::int64_t)
    real,   ///< a deterministic real number
    timing, ///< wall-clock milliseconds: differs between runs of the same point
};

/// Where a statistic is shown (bit mask).
enum StatUse : unsigned {
    in_study = 1,  ///< a column of the study's CSV (study.csv)
    in_detect = 2, ///< a key of `tethash detect --stats` JSON
    in_bench = 4,  ///< on tethash_bench's work line, as `bench_label`
    everywhere = in_study | in_detect | in_bench,
};

struct StatField {
    const char* name; ///< column / key; the DetectStats member's name unless `derived`
    const char* unit; ///< "ms", "length", "buckets", "bytes", "" (a count or a ratio)
    StatKind kind;
    double (*get)(const DetectStats&);
    unsigned use;            ///< StatUse bits
    const char* bench_label; ///< label on tethash_bench's work line (with in_bench)
    bool derived = false;    ///< computed from other fields, not a member of DetectStats
};

/// Member M of DetectStats as a double (StatField::get of the fields that are members).
template <auto M> double member(const DetectStats& s)
{
    return static_cast<double>(s.*M);
}

/// Every field of DetectStats once (tests/test_study_stats_table.cpp checks it), plus derived ratios.
/// Order: the parameters used, the scene, the work counters, the result and memory, candidate reuse, the timings.
inline constexpr std::array<StatField, 30> k_detect_stats = {{
    {"cell_size", "length", StatKind::real, member<&DetectStats::cell_size>, everywhere, "cell"},
    {"table_size", "buckets", StatKind::count, member<&DetectStats::table_size>, everywhere, "table"},
    {"threads", "", StatKind::count, member<&DetectStats::threads>, in_study | in_detect, nullptr},
    {"vertices", "", StatKind::count, member<&DetectStats::vertices>, in_study, nullptr},
    {"tets", "", StatKind::count, member<&DetectStats::tets>, in_study, nullptr},
    {"cells_visited", "", StatKind::count, member<&DetectStats::cells_visited>, everywhere, "cells"},
    {"entries_scanned", "", StatKind::count, member<&DetectStats::entries_scanned>, everywhere, "scanned"},
    {"hash_collisions", "", StatKind::count, member<&DetectStats::hash_collisions>, everywhere, "collisions"},
    {"collision_rate", "", StatKind::real,
     [](const DetectStats& s) {
         return s.entries_scanned ? static_cast<double>(s.hash_collisions) / static_cast<double>(s.entries_scanned)
                                  : 0.0;
     },
     in_study, nullptr, true},
    {"box_rejections", "", StatKind::count, member<&DetectStats::box_rejections>, everywhere, "box-rejected"},
    {"own_vertex_skips", "", StatKind::count, member<&DetectStats::own_vertex_skips>, everywhere, "own"},
    {"candidates", "", StatKind::count, member<&DetectStats::candidates>, in_study | in_detect, nullptr},
    {"nodes", "", StatKind::count, member<&DetectStats::nodes>, in_study | in_detect, nullptr},
    {"ray_tests", "", StatKind::count, member<&DetectStats::ray_tests>, in_study | in_detect, nullptr},
    {"portal_overlaps", "", StatKind::count, member<&DetectStats::portal_overlaps>, in_study | in_detect, nullptr},
    {"inside_tests", "", StatKind::count, member<&DetectStats::inside_tests>, everywhere, "inside tests"},
    {"exact_fallbacks", "", StatKind::count, member<&DetectStats::exact_fallbacks>, everywhere, "exact"},
    {"degenerate_tets", "", StatKind::count, member<&DetectStats::degenerate_tets>, everywhere, "degenerate"},
    {"contacts", "", StatKind::count, member<&DetectStats::contacts>, in_study, nullptr},
    {"table_load", "", StatKind::real, member<&DetectStats::table_load>, in_study | in_detect, nullptr},
    {"memory_bytes", "bytes", StatKind::count, member<&DetectStats::memory_bytes>, in_study | in_detect, nullptr},
    {"skin", "length", StatKind::real, member<&DetectStats::skin>, in_detect, nullptr},
    {"reused", "", StatKind::count, member<&DetectStats::reused>, in_detect, nullptr},
    {"cached_candidates", "", StatKind::count, member<&DetectStats::cached_candidates>, in_detect, nullptr},
    {"ms_total", "ms", StatKind::timing, member<&DetectStats::ms_total>, in_study, nullptr},
    {"ms_setup", "ms", StatKind::timing, member<&DetectStats::ms_setup>, in_detect, nullptr},
    {"ms_vertices", "ms", StatKind::timing, member<&DetectStats::ms_vertices>, in_study | in_detect, nullptr},
    {"ms_tets", "ms", StatKind::timing, member<&DetectStats::ms_tets>, in_study | in_detect, nullptr},
    {"ms_inside", "ms", StatKind::timing, member<&DetectStats::ms_inside>, in_study | in_detect, nullptr},
    {"ms_sort", "ms", StatKind::timing, member<&DetectStats::ms_sort>, in_study | in_detect, nullptr},
}};

/// The value as CSV/table text: an integer for counts, up to 10 significant digits otherwise (table.hpp: fmt_double).
std::string stat_text(const StatField& field, const DetectStats& stats);
/// The member "name": value (an integer for counts, a number that round-trips otherwise).
void write_stat(JsonWriter& j, const StatField& field, const DetectStats& stats);

/// Every field of a BSP tree's statistics as a member "name": value, in declaration order, named as the field:
/// counts as integers, `flipped` as true or false.
void write_stats(JsonWriter& j, const BspStats& stats);

} // namespace tethash::study
