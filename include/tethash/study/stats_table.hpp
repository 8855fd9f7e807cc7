#pragma once
/// \file study/stats_table.hpp
/// The detector's statistics (detect.hpp: DetectStats) as one table: each field's name (the study's CSV column,
/// the key of `tethash detect --stats`), unit, kind and where it is shown. The study, the `detect` command and
/// tethash_bench list the statistics from here, in this order.

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

/// Every field of DetectStats once (tests/test_study_stats_table.cpp checks it), plus derived ratios.
/// Order: the parameters used, the scene, the work counters, the result and memory, candidate reuse, the timings.
inline constexpr std::array<StatField, 28> k_detect_stats = {{
    {"cell_size", "length", StatKind::real, [](const DetectStats& s) { return s.cell_size; },
     in_study | in_detect | in_bench, "cell"},
    {"table_size", "buckets", StatKind::count, [](const DetectStats& s) { return double(s.table_size); },
     in_study | in_detect | in_bench, "table"},
    {"threads", "", StatKind::count, [](const DetectStats& s) { return double(s.threads); }, in_study | in_detect,
     nullptr},
    {"vertices", "", StatKind::count, [](const DetectStats& s) { return double(s.vertices); }, in_study, nullptr},
    {"tets", "", StatKind::count, [](const DetectStats& s) { return double(s.tets); }, in_study, nullptr},
    {"cells_visited", "", StatKind::count, [](const DetectStats& s) { return double(s.cells_visited); },
     in_study | in_detect | in_bench, "cells"},
    {"entries_scanned", "", StatKind::count, [](const DetectStats& s) { return double(s.entries_scanned); },
     in_study | in_detect | in_bench, "scanned"},
    {"hash_collisions", "", StatKind::count, [](const DetectStats& s) { return double(s.hash_collisions); },
     in_study | in_detect | in_bench, "collisions"},
    {"collision_rate", "", StatKind::real,
     [](const DetectStats& s) {
         return s.entries_scanned ? static_cast<double>(s.hash_collisions) / static_cast<double>(s.entries_scanned)
                                  : 0.0;
     },
     in_study, nullptr, true},
    {"box_rejections", "", StatKind::count, [](const DetectStats& s) { return double(s.box_rejections); },
     in_study | in_detect | in_bench, "box-rejected"},
    {"own_vertex_skips", "", StatKind::count, [](const DetectStats& s) { return double(s.own_vertex_skips); },
     in_study | in_detect | in_bench, "own"},
    {"candidates", "", StatKind::count, [](const DetectStats& s) { return double(s.candidates); }, in_study | in_detect,
     nullptr},
    {"nodes", "", StatKind::count, [](const DetectStats& s) { return double(s.nodes); }, in_study | in_detect, nullptr},
    {"inside_tests", "", StatKind::count, [](const DetectStats& s) { return double(s.inside_tests); },
     in_study | in_detect | in_bench, "inside tests"},
    {"exact_fallbacks", "", StatKind::count, [](const DetectStats& s) { return double(s.exact_fallbacks); },
     in_study | in_detect | in_bench, "exact"},
    {"degenerate_tets", "", StatKind::count, [](const DetectStats& s) { return double(s.degenerate_tets); },
     in_study | in_detect | in_bench, "degenerate"},
    {"contacts", "", StatKind::count, [](const DetectStats& s) { return double(s.contacts); }, in_study, nullptr},
    {"table_load", "", StatKind::real, [](const DetectStats& s) { return s.table_load; }, in_study | in_detect,
     nullptr},
    {"memory_bytes", "bytes", StatKind::count, [](const DetectStats& s) { return double(s.memory_bytes); },
     in_study | in_detect, nullptr},
    {"skin", "length", StatKind::real, [](const DetectStats& s) { return s.skin; }, in_detect, nullptr},
    {"reused", "", StatKind::count, [](const DetectStats& s) { return double(s.reused); }, in_detect, nullptr},
    {"cached_candidates", "", StatKind::count, [](const DetectStats& s) { return double(s.cached_candidates); },
     in_detect, nullptr},
    {"ms_total", "ms", StatKind::timing, [](const DetectStats& s) { return s.ms_total; }, in_study, nullptr},
    {"ms_setup", "ms", StatKind::timing, [](const DetectStats& s) { return s.ms_setup; }, in_detect, nullptr},
    {"ms_vertices", "ms", StatKind::timing, [](const DetectStats& s) { return s.ms_vertices; }, in_study | in_detect,
     nullptr},
    {"ms_tets", "ms", StatKind::timing, [](const DetectStats& s) { return s.ms_tets; }, in_study | in_detect, nullptr},
    {"ms_inside", "ms", StatKind::timing, [](const DetectStats& s) { return s.ms_inside; }, in_study | in_detect,
     nullptr},
    {"ms_sort", "ms", StatKind::timing, [](const DetectStats& s) { return s.ms_sort; }, in_study | in_detect, nullptr},
}};

/// The value as CSV/table text: an integer for counts, up to 10 significant digits otherwise (table.hpp: fmt_double).
std::string stat_text(const StatField& field, const DetectStats& stats);
/// The member "name": value (an integer for counts, a number that round-trips otherwise).
void write_stat(JsonWriter& j, const StatField& field, const DetectStats& stats);

} // namespace tethash::study
