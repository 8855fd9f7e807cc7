// The Detector: stage 1 (vertex table, hash_grid.cpp), stage 2 (tet boxes → bucket ranges → candidate
// vertices, SIMD scan), stage 3 (closed inside test by lazily built face planes with a filtered exact
// fallback), then a deterministic merge sorted by (vertex, tet).
#include "tethash/detect.hpp"

#include "detect_checks.hpp"
#include "hash_grid.hpp"
#include "partition_detect.hpp"
#include "scan.hpp"
#include "team.hpp"
#include "tethash/error.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash {

// ---- the detector --------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

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
        cells += o.cells;
        scanned += o.scanned;
        collisions += o.collisions;
        box_rejections += o.box_rejections;
        own += o.own;
        inside_tests += o.inside_tests;
        exact += o.exact;
        degenerate += o.degenerate;
    }
};

struct alignas(64) ThreadState {
    std::vector<Index> candidates; // grown only, never shrunk; `used` entries valid
    std::size_t used = 0;
    std::vector<double> values;     // stage 3: 4 plane values per candidate of a run
    std::vector<std::int8_t> codes; // stage 3: filter outcome per candidate of a run
    std::vector<CandidateRun> runs; // grown only; `num_runs` entries valid
    std::size_t num_runs = 0;
    std::vector<RawContact> contacts;
    std::vector<RawContact> sorted; // radix sort buffer
    Counters counters;
    double ms_tets = 0, ms_inside = 0, ms_sort = 0;
    bool too_many_cells = false;
    Index too_many_cells_tet = -1;
};

int resolve_threads(int requested)
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

} // namespace

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
    void stage_inside(ThreadState& ts, const CandidateRun* runs, std::size_t num_runs, const Index* candidates,
                      const double* P);
    bool moved_less_than(const double* P, int T, double limit) const;
    void remember_positions(const double* P);
    void keep_for_reuse(const double* P, Index m);
    std::int64_t memory_bytes() const;
};

void DetectorImpl::prepare(const PositionsRef& positions)
{
    detail::check_positions(positions, num_vertices);
    const Eigen::Map<const Tets> tet_map(tets.data(), static_cast<Eigen::Index>(tets.size() / 4), 4);
    switch (params.cell_size_mode) {
    case DetectParams::CellSizeMode::absolute:
        cell_size = params.cell_size;
        break;
    case DetectParams::CellSizeMode::auto_mean_edge:
    case DetectParams::CellSizeMode::factor_of_mean_edge: {
        const double mean = mean_edge_length(positions, tet_map);
        const double factor =
            params.cell_size_mode == DetectParams::CellSizeMode::auto_mean_edge ? 1.0 : params.cell_size;
        cell_size = mean > 0 && std::isfinite(mean) ? factor * mean : 1.0;
        break;
    }
    }
    if (!(cell_size > 0) || !std::isfinite(cell_size))
        throw Error("cell size must be positive and finite, got " + std::to_string(cell_size));
    inv_cell = 1.0 / cell_size;
    skin = params.skin_mode == DetectParams::SkinMode::factor_of_cell_size ? params.skin * cell_size : params.skin;
    if (!std::isfinite(skin))
        throw Error("skin " + std::to_string(params.skin) + " × cell size " + std::to_string(cell_size) +
                    " is not a finite length");
    // Reuse needs a displacement strictly below skin / 2 per axis, after rounding of the difference that is
    // measured (relative error ≤ 2^-53): the limit sits a relative 1e-12 below. Skins below 1e-290 are treated as
    // off (the limit would lose its margin in subnormal arithmetic).
    if (!(skin >= 1e-290)) skin = 0;
    set_skin = skin;
    reuse_limit = 0.5 * skin * (1.0 - 1e-12);
    cache_valid = false;
    paused = false;
    reuses_since_full = 0;
    if (num_vertices > 0) {
        const Eigen::RowVector3d lo = positions.colwise().minCoeff(), hi = positions.colwise().maxCoeff();
        for (int a = 0; a < 3; ++a)
            origin[a] = 0.5 * (lo(a) + hi(a));
    }
    const std::int64_t counts[2] = {static_cast<std::int64_t>(dynamic_ids.size()),
                                    static_cast<std::int64_t>(static_ids.size())};
    for (int k = 0; k < 2; ++k)
        table_sizes[k] = params.table_size > 0 ? params.table_size : auto_table_size(params.hash, counts[k]);
    // Static vertices: hashed once (the hash only; the other methods keep their own structures).
    if (params.method == Method::hash &&
        !tables[1].build(positions.data(), static_ids.data(), static_cast<Index>(static_ids.size()), cell_size, origin,
                         table_sizes[1], params.hash, resolve_threads(params.threads)))
        diagnose_build_failure(positions, static_ids.data(), static_cast<Index>(static_ids.size()));
    prepared = true;
}

void DetectorImpl::diagnose_build_failure(const PositionsRef& positions, const Index* ids, Index count) const
{
    detail::check_positions(positions, num_vertices); // non-finite first
    for (Index i = 0; i < count; ++i) {
        const Index v = ids ? ids[i] : i;
        for (int a = 0; a < 3; ++a)
            if (!(std::fabs(positions(v, a) / cell_size) < max_cell_coordinate)) {
                std::ostringstream s;
                s << "vertex " << v << ": coordinate " << positions(v, a) << " / cell size " << cell_size
                  << " is outside the grid's cell range ±2^30; use a larger cell size";
                throw Error(s.str());
            }
    }
    throw Error("vertex table could not be built");
}

std::int64_t DetectorImpl::memory_bytes() const
{
    std::int64_t m = static_cast<std::int64_t>(tets.capacity() + vertex_object.capacity() + tet_object.capacity() +
                                               dynamic_ids.capacity() + static_ids.capacity()) *
                     4;
    m += tables[0].memory_bytes() + tables[1].memory_bytes();
    m += static_cast<std::int64_t>(reference.capacity() * sizeof(double) + chunks.capacity() * sizeof(ChunkRuns) +
                                   last_chunk.capacity() * sizeof(std::int64_t));
    for (const ThreadState& ts : threads)
        m += static_cast<std::int64_t>(
            ts.candidates.capacity() * sizeof(Index) + ts.codes.capacity() + ts.values.capacity() * sizeof(double) +
            ts.runs.capacity() * sizeof(CandidateRun) + ts.contacts.capacity() * sizeof(RawContact) +
            ts.sorted.capacity() * sizeof(RawContact) + sizeof(ThreadState));
    return m;
}

// Stage 2 for one tet: box, cell range, bucket ranges, SIMD scan → candidate run. `with_stats`: also count
// degenerate tets and every scan statistic (a slower scan kernel that classifies every entry).
void DetectorImpl::stage_tets(ThreadState& ts, Index t, const double* P, bool with_stats)
{
    const Index* tv = tets.data() + 4 * static_cast<std::size_t>(t);
    const double* a = P + 3 * static_cast<std::size_t>(tv[0]);
    const double* b = P + 3 * static_cast<std::size_t>(tv[1]);
    const double* c = P + 3 * static_cast<std::size_t>(tv[2]);
    const double* d = P + 3 * static_cast<std::size_t>(tv[3]);
    if (with_stats) {
        const predicates::Orientation o = predicates::orient3d(a, b, c, d);
        if (o.sign == 0) ++ts.counters.degenerate;
    }
    detail::ScanQuery q;
    std::int32_t c0[3], c1[3];
    // With a skin the box is inflated by it (clamped to the guarded cell range, beyond which no vertex is hashed):
    // the candidates then stay valid while every vertex moves less than skin / 2 (see detect()).
    const double limit = max_cell_coordinate * cell_size;
    for (int k = 0; k < 3; ++k) {
        const double lo = std::max(std::min(std::min(a[k], b[k]), std::min(c[k], d[k])) - skin, -limit);
        const double hi = std::min(std::max(std::max(a[k], b[k]), std::max(c[k], d[k])) + skin, limit);
        // The same expressions as the vertex table's (p · (1/l), floor): monotone, so a vertex in the box has
        // its cell in [c0, c1]. Float box relative to the origin: rounding is monotone too, never a false reject.
        c0[k] = floor_to_int(lo * inv_cell);
        c1[k] = floor_to_int(hi * inv_cell);
        q.lo[k] = static_cast<float>(lo - origin[k]);
        q.hi[k] = static_cast<float>(hi - origin[k]);
    }
    for (int k = 0; k < 4; ++k)
        q.own[k] = tv[k];
    const std::int64_t nx = std::int64_t{c1[0]} - c0[0] + 1, ny = std::int64_t{c1[1]} - c0[1] + 1,
                       nz = std::int64_t{c1[2]} - c0[2] + 1;
    const bool column = params.hash == HashFunction::column;
    if ((column ? nx * ny : nx * ny * nz) > max_cells_per_tet) {
        if (!ts.too_many_cells) ts.too_many_cells_tet = t;
        ts.too_many_cells = true;
        return;
    }
    if (with_stats) ts.counters.cells += nx * ny * nz;
    // Tiny cells: the entries' 32-bit cell keys are no longer exact over this tet's cell box (see cell_key).
    const double* exact = nx > key_exact_xy || ny > key_exact_xy || nz > key_exact_z ? P : nullptr;

    const std::int32_t run_begin = static_cast<std::int32_t>(ts.used);
    // Table 0 holds the moving vertices, table 1 the static ones: static tets never look at table 1.
    const int num_tables =
        any_static && !flags.is_static[static_cast<std::size_t>(tet_object[static_cast<std::size_t>(t)])] ? 2 : 1;
    detail::ScanCounters sc;
    const std::int32_t x0 = c0[0], x1 = c1[0], y0 = c0[1], y1 = c1[1];
    for (int ti = 0; ti < num_tables; ++ti) {
        const VertexTable& table = tables[ti];
        if (table.size() == 0) continue;
        const TableModulus& mod = table.modulus();
        const std::int32_t* start = table.start.data();
        q.z0 = c0[2];
        q.z1 = c1[2];
        // Bucket ranges collected in a fixed local array and scanned in batches (no per-range call).
        constexpr int max_ranges = 64;
        detail::ScanRange ranges[max_ranges];
        int nr = 0;
        std::size_t total = 0;
        auto flush = [&]() {
            if (nr == 0) return;
            const std::size_t need = ts.used + total + 8; // the AVX2 scan stores 8 ids at a time
            if (ts.candidates.size() < need) ts.candidates.resize(need + need / 4 + 64);
            ts.used += static_cast<std::size_t>(detail::scan_ranges(
                table, ranges, nr, q, ts.candidates.data() + ts.used, sc, with_stats, exact, inv_cell));
            nr = 0;
            total = 0;
        };
        // Appends a range, dropping it (branch-free) when empty; room for one more range must be left by the caller.
        auto push = [&](std::int32_t begin, std::int32_t end, std::int32_t x, std::int32_t y) {
            ranges[nr] = {begin, end, x, y};
            nr += begin < end;
            total += static_cast<std::size_t>(std::max(end - begin, 0));
        };
        auto add = [&](std::int32_t begin, std::int32_t end, std::int32_t x, std::int32_t y) {
            push(begin, end, x, y);
            if (nr == max_ranges) flush();
        };
        if (column && mod.pow2 && static_cast<std::uint64_t>(nz) < mod.n && 2 * nx * ny <= max_ranges) {
            // The common case: one contiguous range per column unless it wraps around the table's end (then two),
            // all of a tet's columns in one batch.
            const std::uint64_t mask = mod.mask, n = mod.n;
            const std::uint64_t zoff = static_cast<std::uint64_t>(static_cast<std::int64_t>(c0[2]));
            // One flat loop over the nx × ny columns (one loop exit to predict instead of nx + 1).
            std::int32_t x = x0, y = y0;
            for (std::int64_t j = nx * ny; j > 0; --j) {
                const std::uint64_t b0 = (column_mix(x, y) + zoff) & mask;
                const std::uint64_t e = b0 + static_cast<std::uint64_t>(nz);
                if (e <= n) [[likely]] {
                    push(start[b0], start[e], x, y);
                } else {
                    push(start[b0], start[n], x, y);
                    push(start[0], start[e - n], x, y);
                }
                const bool wrap = y == y1;
                x += wrap;
                y = wrap ? y0 : y + 1;
            }
        } else if (column) {
            for (std::int32_t x = x0; x <= x1; ++x)
                for (std::int32_t y = y0; y <= y1; ++y) {
                    const std::uint64_t h = column_mix(x, y);
                    if (static_cast<std::uint64_t>(nz) >= mod.n) {
                        add(0, table.size(), x, y);
                    } else {
                        const std::uint64_t b0 = mod.column_bucket(h, c0[2]);
                        const std::uint64_t b1 = b0 + static_cast<std::uint64_t>(nz) - 1;
                        if (b1 < mod.n) {
                            add(start[b0], start[b1 + 1], x, y);
                        } else {
                            add(start[b0], start[mod.n], x, y);
                            add(start[0], start[b1 - mod.n + 1], x, y);
                        }
                    }
                }
        } else {
            // Teschner's hash: one range per cell, one batch per z-layer (the query's z-run is that layer).
            for (std::int32_t z = c0[2]; z <= c1[2]; ++z) {
                q.z0 = q.z1 = z;
                for (std::int32_t x = x0; x <= x1; ++x)
                    for (std::int32_t y = y0; y <= y1; ++y) {
                        const std::uint64_t bk = mod.reduce(teschner_hash(x, y, z));
                        add(start[bk], start[bk + 1], x, y);
                    }
                flush();
            }
        }
        flush();
    }
    if (with_stats) {
        ts.counters.scanned += sc.scanned;
        ts.counters.collisions += sc.collisions;
        ts.counters.box_rejections += sc.box_rejections;
        ts.counters.own += sc.own;
    }
    std::int32_t run_end = static_cast<std::int32_t>(ts.used);
    // Self-collision off for this tet's object: drop the candidates of the same object here, so that the kept
    // candidates of a skin are already filtered.
    const Index to = tet_object[static_cast<std::size_t>(t)];
    if (any_self_off && !flags.self_collision[static_cast<std::size_t>(to)]) {
        Index* cand = ts.candidates.data();
        std::int32_t kept = run_begin;
        for (std::int32_t j = run_begin; j < run_end; ++j)
            if (vertex_object[static_cast<std::size_t>(cand[j])] != to) cand[kept++] = cand[j];
        run_end = kept;
        ts.used = static_cast<std::size_t>(kept);
    }
    // Branch-free append (most tets have candidates, but not predictably which).
    if (ts.num_runs == ts.runs.size()) ts.runs.resize(std::max<std::size_t>(64, 2 * ts.runs.size()));
    ts.runs[ts.num_runs] = {t, run_begin, run_end};
    ts.num_runs += run_end > run_begin;
}

// Stage 3 over a thread's candidate runs: face planes per tet (only tets with candidates), filtered
// plane tests for all candidates of the tet at once (AVX2 where available), exact orientation only where
// the filter cannot decide.
void DetectorImpl::stage_inside(ThreadState& ts, const CandidateRun* runs, std::size_t num_runs,
                                const Index* candidates, const double* P)
{
    for (std::size_t r = 0; r < num_runs; ++r) {
        const CandidateRun& run = runs[r];
        const Index t = run.tet;
        const Index* tv = tets.data() + 4 * static_cast<std::size_t>(t);
        const double* A = P + 3 * static_cast<std::size_t>(tv[0]);
        const double* B = P + 3 * static_cast<std::size_t>(tv[1]);
        const double* C = P + 3 * static_cast<std::size_t>(tv[2]);
        const double* D = P + 3 * static_cast<std::size_t>(tv[3]);
        const Index* cand = candidates + run.begin;
        const std::int32_t count = run.end - run.begin; // > 0; the self-collision rule was applied in stage 2
        // Face planes with the tet's orientation folded in (AVX2: four faces in four lanes); the orientation's
        // exact sign comes from face 3's plane at D.
        detail::FacePlanes f;
        bool tet_exact = false;
        const int tet_sign = detail::face_planes(A, B, C, D, f, tet_exact);
        ts.counters.exact += tet_exact;
        if (tet_sign == 0) continue;
        const double s = tet_sign;
        if (ts.codes.size() < static_cast<std::size_t>(count)) {
            ts.codes.resize(std::max<std::size_t>(static_cast<std::size_t>(count), 2 * ts.codes.size()));
            ts.values.resize(4 * ts.codes.size());
        }
        detail::filter_candidates(f, P, cand, count, ts.values.data(), ts.codes.data());
        ts.counters.inside_tests += count;
        for (std::int32_t j = 0; j < count; ++j) {
            const int code = ts.codes[static_cast<std::size_t>(j)];
            if (code < 0) continue;
            const Index v = cand[j];
            double* val = ts.values.data() + 4 * static_cast<std::size_t>(j);
            if (code) {
                const double* p = P + 3 * static_cast<std::size_t>(v);
                bool outside = false;
                for (int i = 0; i < 4 && !outside; ++i) {
                    if (!(code & (1 << i))) continue;
                    predicates::Orientation e;
                    switch (i) {
                    case 0:
                        e = predicates::orient3d_exact(p, B, C, D);
                        break;
                    case 1:
                        e = predicates::orient3d_exact(A, p, C, D);
                        break;
                    case 2:
                        e = predicates::orient3d_exact(A, B, p, D);
                        break;
                    default:
                        e = predicates::orient3d_exact(A, B, C, p);
                        break;
                    }
                    ++ts.counters.exact;
                    if (e.sign * tet_sign < 0) outside = true;
                    val[i] = e.value * s;
                }
                if (outside) continue;
            }
            const double sum = val[0] + val[1] + val[2] + val[3];
            RawContact rc;
            rc.vertex = v;
            rc.tet = t;
            for (int i = 0; i < 4; ++i)
                rc.bary[i] = val[i] == 0.0 ? 0.0 : val[i] / sum;
            ts.contacts.push_back(rc);
        }
    }
}

// Skin: true when every moving vertex moved less than `limit` per axis since the remembered positions (the last full
// detection; reuse_limit < skin / 2 allows reuse). A non-finite coordinate counts as moved too far (the full detection
// then reports it). Blocks of 1,024 values with an early exit; parallel over the team for big scenes only (a region
// costs more than checking 20,000 vertices).
bool DetectorImpl::moved_less_than(const double* P, int T, double limit) const
{
    const double h = limit;
    const double* R = reference.data();
    const std::int64_t n = static_cast<std::int64_t>(dynamic_ids.size());
    const Index* ids = dynamic_ids.data();
    constexpr std::int64_t block = 1024;
    const std::int64_t blocks = (n + block - 1) / block;
    int far = 0;
#pragma omp parallel for schedule(static) reduction(| : far) num_threads(T) if (T > 1 && n >= 65536)
    for (std::int64_t b = 0; b < blocks; ++b) {
        if (far) continue;
        const std::int64_t i0 = b * block, i1 = std::min(n, i0 + block);
        int bad = 0;
        if (!any_static) { // all vertices move: one contiguous pass over both arrays
            for (std::int64_t i = 3 * i0; i < 3 * i1; ++i)
                bad |= !(std::fabs(P[i] - R[i]) < h);
        } else {
            for (std::int64_t i = i0; i < i1; ++i) {
                const double* p = P + 3 * static_cast<std::size_t>(ids[i]);
                const double* r = R + 3 * i;
                bad |= !(std::fabs(p[0] - r[0]) < h) | !(std::fabs(p[1] - r[1]) < h) | !(std::fabs(p[2] - r[2]) < h);
            }
        }
        far |= bad;
    }
    return !far;
}

// Skin: after a full detection, remembers the moving vertices' positions and where each chunk's candidate runs are
// (each thread's chunks are in increasing order, monotonic schedule: a chunk's runs end where the thread's next
// chunk begins, or at the thread's last run).
void DetectorImpl::remember_positions(const double* P)
{
    const std::size_t n = dynamic_ids.size();
    reference.resize(3 * n);
    if (!any_static)
        std::copy(P, P + 3 * n, reference.data());
    else
        for (std::size_t i = 0; i < n; ++i)
            for (int a = 0; a < 3; ++a)
                reference[3 * i + static_cast<std::size_t>(a)] =
                    P[3 * static_cast<std::size_t>(dynamic_ids[i]) + static_cast<std::size_t>(a)];
}

void DetectorImpl::keep_for_reuse(const double* P, Index m)
{
    remember_positions(P);
    reuses_since_full = 0;
    const std::size_t num_chunks = static_cast<std::size_t>((m + chunk_tets - 1) / chunk_tets);
    last_chunk.assign(threads.size(), -1);
    for (std::size_t k = 0; k < num_chunks; ++k) {
        const int r = chunks[k].thread;
        if (last_chunk[static_cast<std::size_t>(r)] >= 0)
            chunks[static_cast<std::size_t>(last_chunk[static_cast<std::size_t>(r)])].end = chunks[k].begin;
        last_chunk[static_cast<std::size_t>(r)] = static_cast<std::int64_t>(k);
    }
    for (std::size_t r = 0; r < threads.size(); ++r)
        if (last_chunk[r] >= 0)
            chunks[static_cast<std::size_t>(last_chunk[r])].end = static_cast<std::int32_t>(threads[r].num_runs);
    cache_threads = static_cast<int>(threads.size());
    cache_valid = true;
}

// Sorts a thread's contacts by (vertex, tet) without any synchronisation: they come out of stage 3 in increasing
// tet order (monotonic dynamic schedule, runs in order), so a stable LSD radix sort by vertex (11-bit digits) does
// it. The result is in ts.contacts.
static void sort_own_contacts(ThreadState& ts, Index num_vertices)
{
    const std::size_t n = ts.contacts.size();
    if (n < 2) return;
    if (ts.sorted.size() < n) ts.sorted.resize(n + n / 2);
    RawContact* src = ts.contacts.data();
    RawContact* dst = ts.sorted.data();
    for (int shift = 0; shift < 31 && (num_vertices - 1) >> shift; shift += 11) {
        std::int32_t count[2048] = {};
        for (std::size_t i = 0; i < n; ++i)
            ++count[(src[i].vertex >> shift) & 2047];
        std::int32_t sum = 0;
        for (std::int32_t& c : count) {
            const std::int32_t k = c;
            c = sum;
            sum += k;
        }
        for (std::size_t i = 0; i < n; ++i)
            dst[count[(src[i].vertex >> shift) & 2047]++] = src[i];
        std::swap(src, dst);
    }
    if (src != ts.contacts.data()) std::copy(src, src + n, ts.contacts.data());
}

/// Candidate reuse (skin > 0): when every moving vertex moved less than skin / 2 since the last full detection,
/// the kept candidates contain every contact (docs/detection.md) and only stage 3 runs. Also pauses and resumes
/// the skin (`skin` is the one this call uses).
bool DetectorImpl::decide_reuse(const double* P, int T)
{
    bool reuse = false;
    if (set_skin > 0) {
        if (cache_valid && cache_threads == T) {
            reuse = moved_less_than(P, T, reuse_limit);
            if (reuse)
                ++reuses_since_full;
            else if (reuses_since_full == 0)
                paused = true; // the last inflated detection bought nothing
        } else if (paused && !reference.empty() && moved_less_than(P, T, 0.5 * reuse_limit)) {
            paused = false; // slow enough since the previous call for a kept candidate list to last
        }
        skin = paused ? 0.0 : set_skin;
    }
    return reuse;
}

/// Clears the threads' per-call state; a full detection also drops their candidates.
void DetectorImpl::reset_threads(bool reuse)
{
    for (ThreadState& ts : threads) {
        if (!reuse) {
            ts.used = 0;
            ts.num_runs = 0;
        }
        ts.contacts.clear();
        ts.counters = Counters{};
        ts.too_many_cells = false;
    }
}

/// Stage 3 over the kept candidates (candidate reuse).
void DetectorImpl::detect_kept(const double* P, int T, Index m, Index num_chunks, bool with_stats)
{
    // Stage 3 only, over the kept runs chunk by chunk (monotonic dynamic: each thread's contacts come out in
    // increasing tet order, whichever thread kept the chunk's runs), then each thread sorts its own contacts.
#pragma omp parallel num_threads(T) if (T > 1)
    {
        ThreadState& ts = threads[static_cast<std::size_t>(detail::team_rank())];
        const auto t1 = Clock::now();
#pragma omp for schedule(monotonic : dynamic, 1) nowait
        for (Index k = 0; k < num_chunks; ++k) {
            const ChunkRuns& c = chunks[static_cast<std::size_t>(k)];
            const ThreadState& owner = threads[static_cast<std::size_t>(c.thread)];
            stage_inside(ts, owner.runs.data() + c.begin, static_cast<std::size_t>(c.end - c.begin),
                         owner.candidates.data(), P);
            if (with_stats)
                for (Index t = k * chunk_tets; t < std::min(m, (k + 1) * chunk_tets); ++t) {
                    const Index* tv = tets.data() + 4 * static_cast<std::size_t>(t);
                    ts.counters.degenerate += predicates::orient3d(P + 3 * static_cast<std::size_t>(tv[0]),
                                                                   P + 3 * static_cast<std::size_t>(tv[1]),
                                                                   P + 3 * static_cast<std::size_t>(tv[2]),
                                                                   P + 3 * static_cast<std::size_t>(tv[3]))
                                                  .sign == 0;
                }
        }
        ts.ms_tets = 0;
        ts.ms_inside = ms_since(t1);
        const auto t2 = Clock::now();
        sort_own_contacts(ts, num_vertices);
        ts.ms_sort = ms_since(t2);
    }
}

/// Stages 1-3 in one parallel region (stage 1 over the team for big scenes only), then the candidates kept for
/// reuse. Sets `ms_vertices` (stage 1's time since `t_start`).
void DetectorImpl::detect_full(const PositionsRef& positions, int T, Index m, Index num_chunks, bool with_stats,
                               Clock::time_point t_start, double& ms_vertices)
{
    const double* P = positions.data();
    const Index* ids = any_static ? dynamic_ids.data() : nullptr;
    const Index count = static_cast<Index>(dynamic_ids.size());
    cache_valid = false;
    if (skin > 0) chunks.resize(static_cast<std::size_t>(num_chunks));
    tables[0].reserve(count, table_sizes[0], T);
    // Stage 1: moving vertices. Split over the team only for big scenes (VertexTable::team_parts); else built here,
    // before the region: each barrier can cost the team a scheduler time slice on a busy machine.
    const bool team_build = VertexTable::team_parts(count, T) > 1;
    bool built = true;
    if (!team_build) {
        built = tables[0].build_team(P, ids, count, cell_size, origin, table_sizes[0], params.hash);
        ms_vertices = ms_since(t_start);
    }
#pragma omp parallel num_threads(T) if (T > 1 && built)
    {
        const int rank = detail::team_rank();
        ThreadState& ts = threads[static_cast<std::size_t>(rank)];
        bool ok = built;
        if (team_build) { // every thread gets the same answer
            ok = tables[0].build_team(P, ids, count, cell_size, origin, table_sizes[0], params.hash);
            if (rank == 0) {
                built = ok;
                ms_vertices = ms_since(t_start);
            }
        }
        if (ok) {
            const auto t0 = Clock::now();
            const bool keep = skin > 0;
#pragma omp for schedule(monotonic : dynamic, chunk_tets) nowait
            for (Index t = 0; t < m; ++t) {
                if (keep && t % chunk_tets == 0) // a chunk starts: remember where its runs go
                    chunks[static_cast<std::size_t>(t / chunk_tets)] = {rank, static_cast<std::int32_t>(ts.num_runs),
                                                                        0};
                stage_tets(ts, t, P, with_stats);
            }
            ts.ms_tets = ms_since(t0);
            const auto t1 = Clock::now();
            stage_inside(ts, ts.runs.data(), ts.num_runs, ts.candidates.data(), P);
            ts.ms_inside = ms_since(t1);
            const auto t2 = Clock::now();
            sort_own_contacts(ts, num_vertices);
            ts.ms_sort = ms_since(t2);
        }
    }
    if (!built) diagnose_build_failure(positions, ids, count);
    for (const ThreadState& ts : threads)
        if (ts.too_many_cells)
            throw Error("cell size " + std::to_string(cell_size) + " is too small: tet " +
                        std::to_string(ts.too_many_cells_tet) + " would visit more than 2^24 cells" +
                        (skin > 0 ? " with its box inflated by the skin " + std::to_string(skin) +
                                        "; use a larger cell size or a smaller skin"
                                  : "; use a larger cell size"));
    if (skin > 0)
        keep_for_reuse(P, m);
    else if (paused)
        remember_positions(P); // the next call measures its displacement from here
}

/// Merges the threads' sorted runs into `contacts`: sorted by (vertex, tet), the same for any thread count.
void DetectorImpl::merge_contacts()
{
    std::size_t total = 0;
    for (const ThreadState& ts : threads)
        total += ts.contacts.size();
    contacts.resize(total);
    merge_pos.assign(threads.size(), 0);
    std::size_t* pos = merge_pos.data();
    const int runs = static_cast<int>(threads.size());
    for (std::size_t out = 0; out < total; ++out) {
        int best = -1;
        Index bv = 0, bt = 0;
        for (int r = 0; r < runs; ++r) {
            const ThreadState& ts = threads[static_cast<std::size_t>(r)];
            if (pos[r] == ts.contacts.size()) continue;
            const RawContact& rc = ts.contacts[pos[r]];
            if (best < 0 || rc.vertex < bv || (rc.vertex == bv && rc.tet < bt)) {
                best = r;
                bv = rc.vertex;
                bt = rc.tet;
            }
        }
        assert(best >= 0); // total counts every thread's contacts, so one is left while out < total
        const RawContact& rc = threads[static_cast<std::size_t>(best)].contacts[pos[best]++];
        // The output is sorted by (vertex, tet) and has no duplicate: each thread's run is, and runs are disjoint.
        assert(out == 0 || contacts[out - 1].vertex < rc.vertex ||
               (contacts[out - 1].vertex == rc.vertex && contacts[out - 1].tet < rc.tet));
        Contact& c = contacts[out];
        c.vertex = rc.vertex;
        c.tet = rc.tet;
        c.vertex_object = vertex_object[static_cast<std::size_t>(rc.vertex)];
        c.tet_object = tet_object[static_cast<std::size_t>(rc.tet)];
        for (int k = 0; k < 4; ++k)
            c.bary[k] = rc.bary[k];
        c.depth = std::numeric_limits<double>::quiet_NaN();
        c.direction[0] = c.direction[1] = c.direction[2] = 0;
    }
}

/// The statistics of the call that started at `t_start`.
void DetectorImpl::fill_stats(DetectStats& s, int T, Index m, bool reuse, double ms_vertices, double ms_sort) const
{
    const Index count = static_cast<Index>(dynamic_ids.size());
    Counters sum;
    double ms_sort_own = 0;
    s = DetectStats{};
    s.ms_vertices = ms_vertices;
    for (const ThreadState& ts : threads) {
        sum.add(ts.counters);
        s.ms_tets = std::max(s.ms_tets, ts.ms_tets);
        s.ms_inside = std::max(s.ms_inside, ts.ms_inside);
        ms_sort_own = std::max(ms_sort_own, ts.ms_sort);
    }
    s.ms_sort = ms_sort_own + ms_sort;
    s.cell_size = cell_size;
    s.table_size = table_sizes[0];
    s.threads = T;
    s.vertices = num_vertices;
    s.tets = m;
    s.cells_visited = sum.cells;
    s.entries_scanned = sum.scanned;
    s.hash_collisions = sum.collisions;
    s.box_rejections = sum.box_rejections;
    s.own_vertex_skips = sum.own;
    s.inside_tests = sum.inside_tests;
    s.exact_fallbacks = sum.exact;
    s.degenerate_tets = sum.degenerate;
    s.contacts = static_cast<std::int64_t>(contacts.size());
    s.table_load = static_cast<double>(count) / static_cast<double>(table_sizes[0]);
    s.memory_bytes = memory_bytes();
    s.skin = skin;
    s.reused = reuse ? 1 : 0;
    for (const ThreadState& ts : threads)
        s.candidates += static_cast<std::int64_t>(ts.used);
    if (skin > 0)
        for (const ThreadState& ts : threads)
            s.cached_candidates += static_cast<std::int64_t>(ts.used);
}

const std::vector<Contact>& DetectorImpl::detect(const PositionsRef& positions, DetectStats* stats)
{
    const auto t_call = Clock::now();
    if (positions.rows() != num_vertices)
        throw Error("positions has " + std::to_string(positions.rows()) + " rows, expected " +
                    std::to_string(num_vertices) + " (the number of vertices given to set_topology)");
    double ms_setup = 0; // the first call's one-off set-up, reported apart from stage 1
    const bool first = !prepared;
    if (first) {
        prepare(positions);
        ms_setup = ms_since(t_call);
    }
    const auto t_start = Clock::now();
    if (params.method != Method::hash && params.method != Method::automatic)
        return detect_partition(positions, stats, first, t_call, ms_setup);
    // Automatic thread count: one thread for small scenes, where waking the others costs more than it saves
    // (fewer than 2,000 tets: well under 0.2 ms of work at one thread). An explicit count is always honoured.
    const int T = params.threads == 0 && tets.size() / 4 < 2000 ? 1 : resolve_threads(params.threads);
    if (static_cast<int>(threads.size()) != T) threads.resize(static_cast<std::size_t>(T));
    const double* P = positions.data();

    // One parallel region: stage 1 (big scenes: split over the team), stages 2 and 3 (dynamic chunks of tets; each
    // thread then tests its own candidates and sorts its own contacts), no barrier in between; then the merge of the
    // threads' sorted runs.
    const Index m = static_cast<Index>(tets.size() / 4);
    const bool with_stats = stats != nullptr;
    double ms_vertices = 0;
    const bool reuse = decide_reuse(P, T);
    if (set_skin > 0) ms_vertices = ms_since(t_start);
    reset_threads(reuse);
    const Index num_chunks = (m + chunk_tets - 1) / chunk_tets;
    if (reuse)
        detect_kept(P, T, m, num_chunks, with_stats);
    else
        detect_full(positions, T, m, num_chunks, with_stats, t_start, ms_vertices);

    const auto t_merge = Clock::now();
    merge_contacts();
    const double ms_sort = ms_since(t_merge);
    if (stats) {
        fill_stats(*stats, T, m, reuse, ms_vertices, ms_sort);
        stats->ms_setup = ms_setup;
        stats->ms_total = ms_since(t_call);
    }
    return contacts;
}

/// The methods other than the hash: their broad phase, the shared exact stage (partition_detect.cpp).
const std::vector<Contact>& DetectorImpl::detect_partition(const PositionsRef& positions, DetectStats* stats,
                                                           bool first, Clock::time_point t_call, double ms_setup)
{
    detail::PartitionScene scene;
    scene.positions = positions.data();
    scene.num_vertices = num_vertices;
    scene.tets = tets.data();
    scene.num_tets = static_cast<Index>(tets.size() / 4);
    scene.moving_vertices = dynamic_ids;
    scene.static_vertices = static_ids;
    scene.tet_static = tet_static.data();
    scene.cell_size = cell_size;
    scene.params = params.partition;
    // As the hash: one thread for small scenes unless a count is asked for.
    scene.threads = params.threads == 0 && scene.num_tets < 2000 ? 1 : resolve_threads(params.threads);
    scene.first = first;
    if (!first)
        detail::check_positions(positions, num_vertices); // non-finite coordinates (prepare() checked the first)
    partition.detect(params.method, scene, vertex_object.data(), tet_object.data(), flags, contacts, stats);
    if (stats) {
        stats->ms_setup = ms_setup;
        stats->ms_total = ms_since(t_call);
    }
    return contacts;
}

// ---- public wrappers -------------------------------------------------------------------------------

Detector::Detector() : m_impl(std::make_unique<DetectorImpl>()) {}
Detector::Detector(const DetectParams& params) : m_impl(std::make_unique<DetectorImpl>())
{
    set_params(params);
}
Detector::~Detector() = default;
Detector::Detector(Detector&&) noexcept = default;
Detector& Detector::operator=(Detector&&) noexcept = default;

void Detector::set_params(const DetectParams& params)
{
    detail::validate_params(params);
    m_impl->params = params;
    m_impl->prepared = false;
    m_impl->partition.reset();
}

const DetectParams& Detector::params() const
{
    return m_impl->params;
}

void Detector::set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                            std::span<const Index> tet_object, std::span<const ObjectOptions> objects)
{
    detail::check_topology(tets, num_vertices, vertex_object, tet_object);
    DetectorImpl& d = *m_impl;
    const Index m = static_cast<Index>(tets.rows());
    d.num_vertices = num_vertices;
    d.tets.resize(4 * static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t)
        for (int k = 0; k < 4; ++k)
            d.tets[4 * static_cast<std::size_t>(t) + k] = tets(t, k);
    d.vertex_object.assign(vertex_object.begin(), vertex_object.end());
    if (d.vertex_object.empty()) d.vertex_object.assign(static_cast<std::size_t>(num_vertices), 0);
    d.tet_object.assign(tet_object.begin(), tet_object.end());
    if (d.tet_object.empty()) d.tet_object.assign(static_cast<std::size_t>(m), 0);
    d.flags = detail::object_flags(vertex_object, tet_object, objects);
    d.any_static = std::any_of(d.flags.is_static.begin(), d.flags.is_static.end(), [](unsigned char c) { return c; });
    d.any_self_off =
        std::any_of(d.flags.self_collision.begin(), d.flags.self_collision.end(), [](unsigned char c) { return !c; });
    d.tet_static.resize(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t)
        d.tet_static[static_cast<std::size_t>(t)] =
            d.flags.is_static[static_cast<std::size_t>(d.tet_object[static_cast<std::size_t>(t)])];
    d.partition.reset();
    d.dynamic_ids.clear();
    d.static_ids.clear();
    for (Index v = 0; v < num_vertices; ++v)
        (d.flags.is_static[static_cast<std::size_t>(d.vertex_object[static_cast<std::size_t>(v)])] ? d.static_ids
                                                                                                   : d.dynamic_ids)
            .push_back(v);
    d.prepared = false;
}

void Detector::set_topology(const TetMesh& mesh, std::span<const ObjectOptions> objects)
{
    set_topology(mesh.tets, mesh.num_vertices(), mesh.vertex_object, mesh.tet_object, objects);
}

const std::vector<Contact>& Detector::detect(const PositionsRef& positions, DetectStats* stats)
{
    return m_impl->detect(positions, stats);
}

std::vector<Contact>& Detector::contacts()
{
    return m_impl->contacts;
}

} // namespace tethash
