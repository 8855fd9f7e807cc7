#pragma once
/// \file study/spheres.hpp
/// The experiment of the comparison of octree, k-d tree and BSP tree reproduced in docs/results.md: spheres
/// dropped one per frame into the unit box, gravity, sphere-sphere tests and a positional response, a new
/// splitting-plane tree per frame (split_tree.hpp). Every method detects on the same positions each frame; the
/// response uses the one sorted list of colliding pairs, and every method's list must equal it (else
/// RunFailure), so the simulation is the same for all. Per (method, depth, frame): time of build and pair tests,
/// sphere-sphere tests. DIR/spheres.csv (one row per method, depth and frame, flushed) and DIR/spheres.json.

#include "tethash/error.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace tethash::study {

struct SpheresOptions {
    int spheres = 1000;            ///< spheres dropped, one per frame from frame 0
    int frames = 2000;             ///< frames simulated
    std::vector<int> depths{3, 7}; ///< maximum tree depths (not used by brute)
    /// brute, octree, octree-point, kd, kd-point, bsp, bsp-balanced
    std::vector<std::string> methods{"brute", "octree", "octree-point", "kd", "kd-point", "bsp"};
    double radius = 0.03;   ///< sphere radius; the box is the unit cube
    std::uint64_t seed = 1; ///< drop positions
    int leaf_size = 1;      ///< a node with <= leaf_size spheres is not split (1: split to the depth limit)
    double dt = 0.01;       ///< frame time step in s
    std::string out_dir = "spheres";
    std::string command_line;   ///< recorded in spheres.json
    std::string compiler_flags; ///< recorded in spheres.json
};

/// Throws Error naming the option on: spheres outside 1..1000000, frames outside 1..10000000, an empty or
/// unknown or repeated method, depths empty or outside 0..30 or repeated, radius not in (0, 0.25), leaf size < 1,
/// dt not in (0, 1], an output folder that cannot be written.
void check_spheres_options(const SpheresOptions& options);

struct SpheresHooks {
    /// Called after each frame (frame index from 0, frame count).
    std::function<void(int frame, int frames)> on_frame;
    /// Checked between frames: when set, the run stops, keeping the rows so far.
    const std::atomic<bool>* stop = nullptr;
};

/// Totals of one method and depth over the frames run.
struct SpheresSummary {
    std::string method;
    int depth = 0;       ///< 0 for brute
    double total_ms = 0; ///< sum over frames of build + pair tests
    std::int64_t tests = 0;
    std::int64_t collisions = 0;
};

struct SpheresResult {
    int frames_done = 0;
    std::int64_t rows = 0;
    bool interrupted = false;
    std::string csv_path, json_path;
    std::vector<SpheresSummary> summary;
};

/// Runs the experiment (checks the options first). Throws RunFailure if a method's colliding pairs differ
/// from the reference's in a frame (a bug: every method is exact).
SpheresResult run_spheres(const SpheresOptions& options, const SpheresHooks& hooks = {});

} // namespace tethash::study
