#pragma once
// The hash detector behind Detector (private header): the per-thread buffers of stages 2 and 3, the candidate runs
// kept for reuse and the class that holds them. detect.cpp runs the pipeline (set-up, stage 1, the parallel region,
// the merge, the statistics); detect_stages.cpp holds stages 2 and 3 of one tet; detect_reuse.cpp candidate reuse
// (the skin); the other methods' path is partition_detect.cpp.
#include "../broad_phase/partition_detect.hpp"
#include "../timing.hpp"
#include "detect_checks.hpp"
#include "hash_grid.hpp"
#include "scan.hpp"
#include "tethash/detect.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash {

namespace detail {

/// A contact before the merge: 40 bytes.
struct RawContact {
    Index vertex, tet;
    double bary[4];
};

/// Per-tet candidate run in a thread's candidate list.
struct CandidateRun {
    Index tet;
    std::int32_t begin, end;
};

struct Counters {
    std::int64_t cells = 0, scanned = 0, collisions = 0, box_rejections = 0, own = 0, inside_tests = 0, exact = 0,
                 degenerate = 0;
    void add(const Counters& o)
    {
        static constexpr std::int64_t Counters::*fields[] = {
            &Counters::cells, &Counters::scanned,      &Counters::collisions, &Counters::box_rejections,
            &Counters::own,   &Counters::inside_tests, &Counters::exact,      &Counters::degenerate};
        for (std::int64_t Counters::*f : fields)
            this->*f += o.*f;
    }
};

struct alignas(64) ThreadState {
    std::vector<Index> candidates; // grown only, never shrunk; `used` entries valid
    std::size_t used = 0;
    std::vector<double> values;     // stage 3: 4 plane values per candidate the filter kept, of a run
    std::vector<std::int8_t> codes; // stage 3: undecided faces per candidate the filter kept, of a run
    std::vector<std::int32_t> kept; // stage 3: which candidates of a run the filter kept (not certainly outside)
    std::vector<CandidateRun> runs; // grown only; `num_runs` entries valid
    std::size_t num_runs = 0;
    std::vector<RawContact> contacts;
    std::vector<RawContact> sorted; // radix sort buffer
    Counters counters;
    double ms_tets = 0, ms_inside = 0, ms_sort = 0;
    bool too_many_cells = false;
    Index too_many_cells_tet = -1;
};

inline int resolve_threads(int requested)
{
#ifdef TETHASH_HAVE_OPENMP
    return requested > 0 ? requested : std::max(1, omp_get_max_threads());
#else
    (void)requested;
    return 1;
#endif
}

/// Tets per chunk of the stage-2 schedule; a chunk's candidate runs are kept together for reuse.
constexpr Index chunk_tets = 256;

/// Where the candidate runs of one chunk of tets are kept: threads[thread].runs[begin, end).
struct ChunkRuns {
    std::int32_t thread = 0;
    std::int32_t begin = 0, end = 0;
};

/// Largest number of columns (column hash) or cells (Teschner's hash) one tet may visit.
constexpr std::int64_t max_cells_per_tet = std::int64_t{1} << 24;

/// Sorts a thread's contacts by (vertex, tet) (detect_stages.cpp).
void sort_own_contacts(ThreadState& ts, Index num_vertices);

} // namespace detail

// The detector's own names, for the three files that implement it.
using detail::CandidateRun;
using detail::chunk_tets;
using detail::ChunkRuns;
using detail::Clock;
using detail::Counters;
using detail::max_cells_per_tet;
using detail::ms_since;
using detail::RawContact;
using detail::resolve_threads;
using detail::sort_own_contacts;
using detail::ThreadState;

class DetectorImpl {
  public:
    DetectParams params;
    // topology
    Index num_vertices = 0;
    std::vector<Index> tets;          // 4m
    std::vector<Index> vertex_object; // n (zeros if none given)
    std::vector<Index> tet_object;    // m
    detail::ObjectFlags flags;
    std::vector<Index> dynamic_ids, static_ids;
    bool any_static = false, any_self_off = false;
    std::vector<unsigned char> tet_static; // per tet: its object is static (the other methods' broad phases)
    detail::PartitionDetector partition;   // the methods other than the hash
    // per-scene state fixed at the first detect() after set_topology/set_params
    bool prepared = false;
    double cell_size = 0;
    double inv_cell = 1; // 1 / cell_size, the one factor both the vertex table and the tet boxes use
    double origin[3] = {0, 0, 0};
    std::int64_t table_sizes[2] = {1, 1};
    VertexTable tables[2];  // 0: moving vertices (rebuilt each call), 1: static vertices (built once)
    double skin = 0;        // candidate reuse: tet boxes inflated by skin (length; 0 = off or paused)
    double set_skin = 0;    // the skin asked for (length); skin is 0 while reuse is paused
    double reuse_limit = 0; // largest per-axis displacement that still allows reuse (just below set_skin / 2)
    // Paused reuse: a full detection with the skin whose candidates were not reused once means the scene moves too
    // fast for the skin to pay (its inflated boxes cost more candidates); full detections then run without it, and
    // resume it when a call's displacement since the previous call is below reuse_limit / 2 (reuse would last).
    bool paused = false;
    int reuses_since_full = 0;
    // candidate cache (skin > 0): the kept candidates are the threads' candidate runs of the last full detection
    bool cache_valid = false;
    int cache_threads = 0;
    std::vector<double> reference;        // positions of the moving vertices at the last full detection (dynamic order)
    std::vector<ChunkRuns> chunks;        // per chunk of chunk_tets tets: the thread holding its runs and which
    std::vector<std::int64_t> last_chunk; // keep_for_reuse: per thread, its last chunk so far
    // buffers
    std::vector<ThreadState> threads;
    std::vector<Contact> contacts;
    std::vector<std::size_t> merge_pos; // merge: next contact of each thread's run

    void prepare(const PositionsRef& positions);
    void diagnose_build_failure(const PositionsRef& positions, const Index* ids, Index count) const;
    const std::vector<Contact>& detect(const PositionsRef& positions, DetectStats* stats);
    // the stages of detect()
    bool decide_reuse(const double* P, int T);
    void reset_threads(bool reuse);
    void detect_kept(const double* P, int T, Index m, Index num_chunks, bool with_stats);
    void detect_full(const PositionsRef& positions, int T, Index m, Index num_chunks, bool with_stats,
                     Clock::time_point t_start, double& ms_vertices);
    void merge_contacts();
    const std::vector<Contact>& detect_partition(const PositionsRef& positions, DetectStats* stats, bool first,
                                                 Clock::time_point t_call, double ms_setup);
    void fill_stats(DetectStats& s, int T, Index m, bool reuse, double ms_vertices, double ms_sort) const;
    void stage_tets(ThreadState& ts, Index t, const double* P, bool with_stats);
    /// Whether stage_tets_lean can run this call (AVX2, no statistics, column hash, power-of-two tables).
    bool lean_stage_tets(bool with_stats) const;
    /// stage_tets without statistics for the common case (see detect_stages.cpp), with the column hash's scan kernel
    /// `scan` (detail::column_scan_kernel()); the same contacts.
    void stage_tets_lean(ThreadState& ts, Index t, const double* P, detail::ScanKernel scan);
    /// The end of stage 2 for one tet: the self-collision rule on its candidates [run_begin, ts.used), its run.
    void finish_run(ThreadState& ts, Index t, std::int32_t run_begin);
    void stage_inside(ThreadState& ts, const CandidateRun* runs, std::size_t num_runs, const Index* candidates,
                      const double* P);
    bool moved_less_than(const double* P, int T, double limit) const;
    void remember_positions(const double* P);
    void keep_for_reuse(const double* P, Index m);
    std::int64_t memory_bytes() const;
};

} // namespace tethash
