#pragma once
// The broad phases other than the spatial hash (private header; docs/partitions.md). Each one finds candidate
// (vertex, tet) pairs for the exact stage that every method shares (partition_detect.cpp): a candidate set that
// contains every pair whose vertex lies in the tet's closed bounding box. The exact stage applies the object rules,
// skips degenerate tets (the broad phases leave out a tet's own vertices), runs the closed inside test and sorts, so
// every method returns the oracle's contacts bit for bit, whatever its structure and thread count.
#include "tethash/detect.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace tethash::detail {

/// What one detect() call hands a broad phase. Arrays belong to the detector and live through the call.
struct PartitionScene {
    const double* positions = nullptr; ///< num_vertices × 3, row-major
    Index num_vertices = 0;
    const Index* tets = nullptr; ///< num_tets × 4
    Index num_tets = 0;
    std::span<const Index> moving_vertices;    ///< vertices of objects that are not static, increasing
    std::span<const Index> static_vertices;    ///< vertices of static objects, increasing
    const unsigned char* tet_static = nullptr; ///< per tet: 1 when its object is static
    double cell_size = 1;                      ///< the detector's cell size (the grids' cell, the hash's l)
    PartitionParams params;                    ///< as set; 0 fields mean the method's default
    int threads = 1;                           ///< team size to use (1: serial)
    /// True on the first call after set_topology()/set_params(): structures kept across calls (a refitted tree,
    /// static vertices) are built from scratch.
    bool first = true;
};

/// A candidate for the exact stage.
struct CandidatePair {
    Index vertex, tet;
};

/// One thread's candidates. `pairs` is cleared by the detector before each call and only grows.
struct CandidateSink {
    std::vector<CandidatePair> pairs;
};

/// What the structure cost in the last call (milliseconds, the slowest thread's where parallel).
struct BroadPhaseTimes {
    double ms_build = 0; ///< building or refitting the structure
    double ms_query = 0; ///< finding the candidates
};

/// Work of a structure kept across calls, counted since the broad phase was made (zero for the others).
struct BroadPhaseCounts {
    std::int64_t builds = 0;  ///< built or sorted from scratch (the first call's included)
    std::int64_t updates = 0; ///< refitted, or its orders repaired by insertion sort
};

class BroadPhase {
  public:
    virtual ~BroadPhase() = default;
    /// Appends to sinks[r] (r < sinks.size() == scene.threads) every pair (v, t) with vertex v inside the closed
    /// bounding box of tet t, except a tet's own four vertices (never handed on: bp_common.hpp's own_vertex) and
    /// pairs where v and t both belong to static objects (those may be left out). More pairs are allowed (the exact
    /// stage rejects them), but each pair at most once over all sinks. May open its own parallel region of
    /// scene.threads threads; must not depend on the thread count for which pairs it emits. Throws Error when the
    /// structure cannot be built (naming why, e.g. the dense grid's memory).
    virtual BroadPhaseTimes find(const PartitionScene& scene, std::vector<CandidateSink>& sinks) = 0;
    /// Working memory of the structure in bytes (not counting the sinks).
    virtual std::int64_t memory_bytes() const = 0;
    /// Cells, nodes or levels of the structure after the last call (what `DetectStats::nodes` reports; zero for the
    /// methods without any).
    virtual std::int64_t nodes() const { return 0; }
    /// Builds and updates so far (the refitted BVH's builds and refits, sort and sweep's full and repaired sorts).
    virtual BroadPhaseCounts counts() const { return {}; }
    /// Adds the method's own counters of the last call to `stats` (the portals' segment tests and overlaps).
    virtual void add_counters(DetectStats& /*stats*/) const {}
};

/// The broad phase of `method` (not `hash`, not `automatic`).
std::unique_ptr<BroadPhase> make_broad_phase(Method method);
/// The broad phases, one per file (bp_*.cpp): `refit` keeps the BVH across calls (bvh_refit) instead of rebuilding.
std::unique_ptr<BroadPhase> make_brute_force();
std::unique_ptr<BroadPhase> make_uniform_grid();
std::unique_ptr<BroadPhase> make_hierarchical_grid();
std::unique_ptr<BroadPhase> make_sort_sweep();
std::unique_ptr<BroadPhase> make_bvh(bool refit);
std::unique_ptr<BroadPhase> make_loose_octree();
std::unique_ptr<BroadPhase> make_portals();
/// The splitting-plane tree of `method` (octrees, k-d trees, BSP trees: bp_split_tree.cpp); nullptr for the others.
std::unique_ptr<BroadPhase> make_split_tree_broad_phase(Method method);

/// Closed axis-aligned bounding box of tet t (lo[3], hi[3]).
inline void tet_box(const PartitionScene& s, Index t, double lo[3], double hi[3])
{
    const Index* tv = s.tets + 4 * static_cast<std::size_t>(t);
    for (int a = 0; a < 3; ++a) {
        lo[a] = hi[a] = s.positions[3 * static_cast<std::size_t>(tv[0]) + a];
        for (int k = 1; k < 4; ++k) {
            const double x = s.positions[3 * static_cast<std::size_t>(tv[k]) + a];
            lo[a] = x < lo[a] ? x : lo[a];
            hi[a] = x > hi[a] ? x : hi[a];
        }
    }
}

/// Whether point p lies in the closed box [lo, hi].
inline bool in_box(const double* p, const double lo[3], const double hi[3])
{
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] && p[2] <= hi[2];
}

} // namespace tethash::detail
