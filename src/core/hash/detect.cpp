// The Detector: stage 1 (vertex table, hash_grid.cpp), stage 2 (tet boxes → bucket ranges → candidate
// vertices, SIMD scan), stage 3 (closed inside test by lazily built face planes with a filtered exact
// fallback), then a deterministic merge sorted by (vertex, tet).
#include "tethash/detect.hpp"

#include "../team.hpp"
#include "detector_impl.hpp"
#include "tethash/error.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <sstream>

namespace tethash {

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
            ts.candidates.capacity() * sizeof(Index) + ts.codes.capacity() + ts.kept.capacity() * sizeof(std::int32_t) +
            ts.values.capacity() * sizeof(double) + ts.runs.capacity() * sizeof(CandidateRun) +
            ts.contacts.capacity() * sizeof(RawContact) + ts.sorted.capacity() * sizeof(RawContact) +
            sizeof(ThreadState));
    return m;
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
            const bool lean = lean_stage_tets(with_stats);
            const detail::ScanKernel column_scan = detail::column_scan_kernel();
#pragma omp for schedule(monotonic : dynamic, chunk_tets) nowait
            for (Index t = 0; t < m; ++t) {
                if (keep && t % chunk_tets == 0) // a chunk starts: remember where its runs go
                    chunks[static_cast<std::size_t>(t / chunk_tets)] = {rank, static_cast<std::int32_t>(ts.num_runs),
                                                                        0};
                if (lean)
                    stage_tets_lean(ts, t, P, column_scan);
                else
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

void Detector::set_threads(int threads)
{
    DetectParams p = m_impl->params;
    p.threads = threads;
    detail::validate_params(p);
    m_impl->params.threads = threads;
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
