#pragma once
/// \file study/spec.hpp
/// What a study is: the sweep, its scenes and the value lists of its parameters, as the command line gives them.
///
/// Value lists ("specs") are comma-separated items:
///  Single values follow the grammar of every command (detect_grammar.hpp: parse_cell_size, parse_table_size,
///  parse_threads): a plain number is a length or a count, "xF" a factor.
///  - cell size: factors of the scene's mean edge length "x0.5,x1,x2", lengths "0.01", "auto" (= x1), or a
///    log-spaced range of factors "xFROM:xTO:POINTS" (e.g. "x0.125:x8:13") or of lengths "FROM:TO:POINTS".
///  - table size: bucket counts ("1009"), "auto" (the detector's default), "xF" (F × the vertex count,
///    rounded up to the next power of two) or a range "xFROM:xTO:POINTS" / "FROM:TO:POINTS" that gives,
///    for each log-spaced value v, both the next power of two ≥ v and the next prime ≥ v. 0 is invalid.
///  - hash: names of detect.hpp's hash functions ("teschner,column") or "all".
///  - threads: counts ("1,2"; 0 = every hardware thread) or "FROM:TO" (every count in between).
///  - methods: names of detect.hpp's broad phases ("hash,bvh,kd"; parse_method) or "all" (every one but auto).
///  - max depth, leaf size, levels: counts ≥ 1 or "default"; looseness: factors 1..16 or "default". Each applies
///    only to the methods that use it (the others are measured once, the column empty).
///  - integrator: names of the simulator's integrators or "all"; dt: seconds, list or log range
///    "FROM:TO:POINTS"; substeps: counts ≥ 1.

#include "tethash/error.hpp"

#include <string>
#include <vector>

namespace tethash::study {

enum class Sweep { cell_size, table_size, hash, threads, grid, integrator, stability, method };
/// "cell-size", "table-size", "hash", "threads", "grid", "integrator", "stability", "method"; throws Error for
/// anything else.
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
    std::vector<std::string> methods;   ///< broad phases (default: hash; all when the method sweep)
    std::vector<std::string> max_depth; ///< partition parameters (default: the method's)
    std::vector<std::string> leaf_size;
    std::vector<std::string> looseness;
    std::vector<std::string> levels;
    /// Scenes of the space-partition comparison (scenarios.hpp: partition_scene): names or "all".
    std::vector<std::string> partition_scenes;

    std::vector<std::string> integrator; ///< simulator sweep
    std::vector<std::string> dt;
    std::vector<std::string> substeps;
    std::vector<std::string> young;      ///< stability sweep: Young's moduli (Pa)
    std::vector<std::string> mass_ratio; ///< stability sweep: density of the first body over the second
    std::vector<std::string> size;       ///< stability sweep: body sizes (longest extent, m)
    double duration = 0;                 ///< simulated seconds; 0: the scene's own duration
    int samples = 4;                     ///< fixed times (evenly spaced, the last at the end) where errors are taken
    double reference_factor = 16;        ///< the reference run uses dt / reference_factor (of the smallest dt)

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

} // namespace tethash::study
