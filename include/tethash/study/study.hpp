#pragma once
/// \file study/study.hpp
/// Parameter studies: sweeps over the detector's parameters (cell size, table size, hash function, threads,
/// or a grid of any two) and over the simulator's integrator × time step × substeps, measured K times after
/// a warm-up, written as one CSV row per point and repeat (DIR/study.csv) and a summary (DIR/study.json).
///
/// What a study is and its value lists: spec.hpp.

#include "tethash/error.hpp"
#include "tethash/study/spec.hpp"
#include "tethash/study/table.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace tethash::study {

/// One measured point: its parameters as (column, value) text pairs, in column order.
struct PointInfo {
    std::int64_t index = 0;
    std::string scene;
    std::vector<std::pair<std::string, std::string>> params;
    std::string label() const; ///< "scene cell_factor=1 table_size=4096 ..." for progress lines
};

struct StudyPlan; // opaque: scenes, points, columns

/// Validates every option and loads the scenes (no measurement yet). Throws Error on bad input
/// (empty range, cell size ≤ 0, table size 0, unknown names, missing mesh, bad shard).
std::shared_ptr<StudyPlan> plan_study(const StudyOptions& options);
/// Points in the whole study (all shards) and in this shard.
std::int64_t points_total(const StudyPlan& plan);
std::int64_t points_in_shard(const StudyPlan& plan);
const std::vector<std::string>& columns(const StudyPlan& plan);

struct RunHooks {
    /// Called before each point of this shard (k-th of `of`).
    std::function<void(std::int64_t k, std::int64_t of, const PointInfo& point)> on_point;
    /// Called with notes worth showing (oracle computed, penetration unavailable, ...).
    std::function<void(const std::string& note)> on_note;
    /// Checked between points (and between repeats): when set, the study stops, keeping the rows so far.
    const std::atomic<bool>* stop = nullptr;
};

struct StudyResult {
    std::int64_t points_done = 0, points_planned = 0;
    std::int64_t rows = 0;
    bool interrupted = false;
    std::string csv_path, json_path;
    std::vector<std::string> notes;
};

/// Runs the plan: DIR/study.csv row by row (flushed), then DIR/study.json (also when interrupted).
StudyResult run_study(StudyPlan& plan, const RunHooks& hooks = {});

/// Joins the study.csv of several shard folders into `out_dir`/study.csv (rows ordered by point and repeat,
/// identical to an unsharded run apart from timing columns) and writes a study.json whose summary covers
/// all rows and which embeds each shard's study.json (read with a JSON reader: the sweep and the point count).
/// Throws Error on missing files, different headers, a study.json that is not JSON or a point measured twice.
/// Returns the points missing from the merged set (empty when complete).
std::vector<std::int64_t> merge_studies(const std::vector<std::string>& dirs, const std::string& out_dir,
                                        const std::string& command_line);

} // namespace tethash::study
