#pragma once
/// \file study/study.hpp
/// Parameter studies: sweeps over the detector's parameters (cell size, table size, hash function, threads,
/// or a grid of any two) and over the simulator's integrator × time step × substeps, measured K times after
/// a warm-up, written as one CSV row per point and repeat (DIR/study.csv) and a summary (DIR/study.json).
///
/// Value lists ("specs") are comma-separated items:
///  Single values follow the grammar of every command (detect.hpp: parse_cell_size, parse_table_size,
///  parse_threads): a plain number is a length or a count, "xF" a factor.
///  - cell size: factors of the scene's mean edge length "x0.5,x1,x2", lengths "0.01", "auto" (= x1), or a
///    log-spaced range of factors "xFROM:xTO:POINTS" (e.g. "x0.125:x8:13") or of lengths "FROM:TO:POINTS".
///  - table size: bucket counts ("1009"), "auto" (the detector's default), "xF" (F × the vertex count,
///    rounded up to the next power of two) or a range "xFROM:xTO:POINTS" / "FROM:TO:POINTS" that gives,
///    for each log-spaced value v, both the next power of two ≥ v and the next prime ≥ v. 0 is invalid.
///  - hash: names of detect.hpp's hash functions ("teschner,column") or "all".
///  - threads: counts ("1,2"; 0 = every hardware thread) or "FROM:TO" (every count in between).
///  - integrator: names of the simulator's integrators or "all"; dt: seconds, list or log range
///    "FROM:TO:POINTS"; substeps: counts ≥ 1.

#include "tethash/mesh.hpp"
#include "tethash/study/table.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace tethash::study {

enum class Sweep { cell_size, table_size, hash, threads, grid, integrator, stability };
/// "cell-size", "table-size", "hash", "threads", "grid", "integrator", "stability"; throws Error for anything else.
Sweep parse_sweep(const std::string& name);
const char* to_string(Sweep s);

/// Everything the command line gives.
struct StudyOptions {
    Sweep sweep = Sweep::cell_size;
    /// Scenes from mesh files: each entry is one scene; "a.vtu+b.vtu" joins files into one scene of several
    /// objects (vertex and tet ids in argument order).
    std::vector<std::string> meshes;
    std::string scene_file;     ///< a simulator scene (TOML); needed by the integrator sweep
    bool teschner = false;      ///< the five scenarios of Teschner 2003 (scenarios.hpp)
    std::vector<int> scenarios; ///< with `teschner`: which of them (1 .. 5); empty: all five

    std::vector<std::string> cell_size; ///< specs (see above); empty: the sweep's default
    std::vector<std::string> table_size;
    std::vector<std::string> hash;
    std::vector<std::string> threads;
    std::vector<std::string> grid; ///< for Sweep::grid: the two swept parameters (cell-size, table-size, hash, threads)

    std::vector<std::string> integrator; ///< simulator sweep
    std::vector<std::string> dt;
    std::vector<std::string> substeps;
    std::vector<std::string> young;      ///< stability sweep: Young's moduli (Pa)
    std::vector<std::string> mass_ratio; ///< stability sweep: density of the first body over the second
    double duration = 0;          ///< simulated seconds; 0: the scene's own duration
    int samples = 4;              ///< fixed times (evenly spaced, the last at the end) where errors are taken
    double reference_factor = 16; ///< the reference run uses dt / reference_factor (of the smallest dt)

    int repeat = 3; ///< measured repeats per point (after one warm-up)
    int warmup = 1;
    bool oracle = true;                   ///< compare every detection with the brute-force oracle
    bool penetration = true;              ///< measure the penetration-depth error (if available)
    int shard_index = 0, shard_count = 1; ///< run points with index % shard_count == shard_index
    std::string out_dir = "study";
    std::string command_line;   ///< recorded in study.json
    std::string compiler_flags; ///< recorded in study.json
};

/// Parses "I/N" (0 ≤ I < N); throws Error naming the option otherwise.
void parse_shard(const std::string& spec, int& index, int& count);

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
/// all rows and which embeds each shard's study.json. Throws Error on missing files, different headers or a
/// point measured twice. Returns the points missing from the merged set (empty when complete).
std::vector<std::int64_t> merge_studies(const std::vector<std::string>& dirs, const std::string& out_dir,
                                        const std::string& command_line);

/// Machine description for study.json: {"cores", "cpu", "compiler", ...} as JSON object text.
std::string machine_json(const std::string& compiler_flags);

/// Median / min / max per point of every timing column, as a JSON array text (used for study.json).
std::string summary_json(const Table& table);

} // namespace tethash::study
