// The Detector: stage 1 (vertex table, hash_grid.cpp), stage 2 (tet boxes → bucket ranges → candidate
// vertices, SIMD scan), stage 3 (closed inside test by lazily built face planes with a filtered exact
// fallback), then a deterministic merge sorted by (vertex, tet).
#include "tethash/detect.hpp"

#include "detect_checks.hpp"
#include "scan.hpp"
#include "tethash/error.hpp"
#include "tethash/hash_grid.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash {

// ---- names, helpers -----------------------------------------------------------------------------

HashFunction parse_hash_function(const std::string& name)
{
    if (name == "teschner") return HashFunction::teschner;
    if (name == "column") return HashFunction::column;
    throw Error("unknown hash function '" + name + "' (expected teschner or column)");
}

const char* to_string(HashFunction h)
{
    switch (h) {
    case HashFunction::teschner: return "teschner";
    case HashFunction::column: return "column";
    }
    return "?";
}

double mean_edge_length(const PositionsRef& positions, const TetsRef& tets)
{
    const Index n = static_cast<Index>(positions.rows());
    std::vector<std::uint64_t> keys;
    keys.reserve(static_cast<std::size_t>(tets.rows()) * 6);
    static constexpr int pairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
        for (const auto& e : pairs) {
            Index a = tets(t, e[0]), b = tets(t, e[1]);
            if (a < 0 || b < 0 || a >= n || b >= n)
                throw Error("mean_edge_length: tet " + std::to_string(t) + " has a vertex index out of range [0, " +
                            std::to_string(n) + ")");
            if (a == b) continue;
            if (a > b) std::swap(a, b);
            keys.push_back((static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b));
        }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    if (keys.empty()) return 0.0;
    double sum = 0;
    for (std::uint64_t k : keys) {
        const Index a = static_cast<Index>(k >> 32), b = static_cast<Index>(k & 0xffffffffu);
        sum += (positions.row(a) - positions.row(b)).norm();
    }
    return sum / static_cast<double>(keys.size());
}

namespace detail {

void check_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                    std::span<const Index> tet_object)
{
    if (num_vertices < 0) throw Error("number of vertices must be ≥ 0, got " + std::to_string(num_vertices));
    if (!vertex_object.empty() && static_cast<Index>(vertex_object.size()) != num_vertices)
        throw Error("vertex_object has " + std::to_string(vertex_object.size()) + " entries for " +
                    std::to_string(num_vertices) + " vertices");
    if (!tet_object.empty() && static_cast<Eigen::Index>(tet_object.size()) != tets.rows())
        throw Error("tet_object has " + std::to_string(tet_object.size()) + " entries for " +
                    std::to_string(tets.rows()) + " tets");
    for (Eigen::Index t = 0; t < tets.rows(); ++t) {
        for (int k = 0; k < 4; ++k) {
            const Index v = tets(t, k);
            if (v < 0 || v >= num_vertices)
                throw Error("tet " + std::to_string(t) + ": vertex index " + std::to_string(v) + " out of range [0, " +
                            std::to_string(num_vertices) + ")");
            for (int j = 0; j < k; ++j)
                if (tets(t, j) == v)
                    throw Error("tet " + std::to_string(t) + ": vertex index " + std::to_string(v) + " repeated");
        }
    }
    for (std::size_t i = 0; i < vertex_object.size(); ++i)
        if (vertex_object[i] < 0)
            throw Error("vertex " + std::to_string(i) + ": object id " + std::to_string(vertex_object[i]) +
                        " out of range (must be ≥ 0)");
    for (std::size_t i = 0; i < tet_object.size(); ++i)
        if (tet_object[i] < 0)
            throw Error("tet " + std::to_string(i) + ": object id " + std::to_string(tet_object[i]) +
                        " out of range (must be ≥ 0)");
}

void check_positions(const PositionsRef& positions, Index num_vertices)
{
    if (positions.rows() != num_vertices)
        throw Error("positions has " + std::to_string(positions.rows()) + " rows, expected " +
                    std::to_string(num_vertices) + " (the number of vertices given to set_topology)");
    for (Eigen::Index v = 0; v < positions.rows(); ++v)
        if (!std::isfinite(positions(v, 0)) || !std::isfinite(positions(v, 1)) || !std::isfinite(positions(v, 2))) {
            std::ostringstream s;
            s << "vertex " << v << " has a non-finite position (" << positions(v, 0) << ", " << positions(v, 1)
              << ", " << positions(v, 2) << ")";
            throw Error(s.str());
        }
}

ObjectFlags object_flags(std::span<const Index> vertex_object, std::span<const Index> tet_object,
                         std::span<const ObjectOptions> objects)
{
    Index count = 1;
    for (Index o : vertex_object) count = std::max(count, o + 1);
    for (Index o : tet_object) count = std::max(count, o + 1);
    ObjectFlags f;
    f.self_collision.assign(static_cast<std::size_t>(count), 1);
    f.is_static.assign(static_cast<std::size_t>(count), 0);
    for (std::size_t k = 0; k < objects.size() && k < static_cast<std::size_t>(count); ++k) {
        f.self_collision[k] = objects[k].self_collision;
        f.is_static[k] = objects[k].is_static;
    }
    return f;
}

} // namespace detail

// ---- the detector --------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

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
    std::int64_t cells = 0, scanned = 0, collisions = 0, box_rejections = 0, own = 0, inside_tests = 0,
                 exact = 0, degenerate = 0;
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
    std::vector<Index> candidates;      // grown only, never shrunk; `used` entries valid
    std::size_t used = 0;
    std::vector<double> values;         // stage 3: 4 plane values per candidate of a run
    std::vector<std::int8_t> codes;     // stage 3: filter outcome per candidate of a run
    std::vector<detail::BlockHit> hits;      // stage 2, block path: (vertex, lane) hits of one block
    std::vector<CandidateRun> runs;
    std::vector<RawContact> contacts;
    Counters counters;
    double ms_tets = 0, ms_inside = 0;
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
    // per-scene state fixed at the first detect() after set_topology/set_params
    bool prepared = false;
    double cell_size = 0;
    double inv_cell = 1;   // 1 / cell_size, the one factor both the vertex table and the tet boxes use
    double origin[3] = {0, 0, 0};
    std::int64_t table_sizes[2] = {1, 1};
    VertexTable tables[2];   // 0: moving vertices (rebuilt each call), 1: static vertices (built once)
    // buffers
    std::vector<ThreadState> threads;
    std::vector<std::int32_t> vertex_counts;
    std::vector<Contact> contacts;

    void prepare(const PositionsRef& positions);
    void diagnose_build_failure(const PositionsRef& positions, const Index* ids, Index count) const;
    const std::vector<Contact>& detect(const PositionsRef& positions, DetectStats* stats);
    void stage_tets(ThreadState& ts, Index t, const double* P, bool with_stats);
    void stage_block(ThreadState& ts, const Index* ids, int count, const double* P);
    std::vector<Index> tets_sorted;
    std::vector<Index> tet_order;   // tets in Morton order of their centroid cells at the first detect()
    void stage_inside(ThreadState& ts, const double* P);
    std::int64_t memory_bytes() const;
};

void DetectorImpl::prepare(const PositionsRef& positions)
{
    detail::check_positions(positions, num_vertices);
    const Eigen::Map<const Tets> tet_map(tets.data(), static_cast<Eigen::Index>(tets.size() / 4), 4);
    switch (params.cell_size_mode) {
    case DetectParams::CellSizeMode::absolute: cell_size = params.cell_size; break;
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
    if (num_vertices > 0) {
        const Eigen::RowVector3d lo = positions.colwise().minCoeff(), hi = positions.colwise().maxCoeff();
        for (int a = 0; a < 3; ++a) origin[a] = 0.5 * (lo(a) + hi(a));
    }
    const std::int64_t counts[2] = {static_cast<std::int64_t>(dynamic_ids.size()),
                                    static_cast<std::int64_t>(static_ids.size())};
    for (int k = 0; k < 2; ++k)
        table_sizes[k] = params.table_size > 0 ? params.table_size : auto_table_size(params.hash, counts[k]);
    // Tet order for the block path: Morton order of the centroid cells at these positions, so that the eight
    // tets of a block are neighbours (deformation keeps them mostly so). Ties by tet id: deterministic.
    {
        const std::size_t m = tets.size() / 4;
        std::vector<std::pair<std::uint64_t, Index>> keyed(m);
        auto spread = [](std::uint64_t v) {   // 21 bits → every third bit
            v &= 0x1fffff;
            v = (v | v << 32) & 0x1f00000000ffffULL;
            v = (v | v << 16) & 0x1f0000ff0000ffULL;
            v = (v | v << 8) & 0x100f00f00f00f00fULL;
            v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
            v = (v | v << 2) & 0x1249249249249249ULL;
            return v;
        };
        for (std::size_t t = 0; t < m; ++t) {
            std::uint64_t key = 0;
            for (int a = 0; a < 3; ++a) {
                double c = 0;
                for (int k = 0; k < 4; ++k) c += positions(tets[4 * t + k], a);
                const double cell = std::floor((0.25 * c - origin[a]) / cell_size) + 1048576.0;
                const auto u = static_cast<std::uint64_t>(std::clamp(cell, 0.0, 2097151.0));
                key |= spread(u) << a;
            }
            keyed[t] = {key, static_cast<Index>(t)};
        }
        std::sort(keyed.begin(), keyed.end());
        tet_order.resize(m);
        for (std::size_t t = 0; t < m; ++t) tet_order[t] = keyed[t].second;
        tets_sorted.resize(4 * m);
        for (std::size_t t = 0; t < m; ++t)
            for (int k = 0; k < 4; ++k) tets_sorted[4 * t + k] = tets[4 * static_cast<std::size_t>(tet_order[t]) + k];
    }
    // Static vertices: hashed once.
    if (!tables[1].build(positions.data(), static_ids.data(), static_cast<Index>(static_ids.size()), cell_size, origin,
                         table_sizes[1], params.hash, resolve_threads(params.threads)))
        diagnose_build_failure(positions, static_ids.data(), static_cast<Index>(static_ids.size()));
    prepared = true;
}

void DetectorImpl::diagnose_build_failure(const PositionsRef& positions, const Index* ids, Index count) const
{
    detail::check_positions(positions, num_vertices);   // non-finite first
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
    std::int64_t m = static_cast<std::int64_t>(tets.capacity() + tet_order.capacity() + vertex_object.capacity() + tet_object.capacity() +
                                               dynamic_ids.capacity() + static_ids.capacity() +
                                               vertex_counts.capacity()) * 4;
    m += tables[0].memory_bytes() + tables[1].memory_bytes();
    for (const ThreadState& ts : threads)
        m += static_cast<std::int64_t>(ts.candidates.capacity() * sizeof(Index) + ts.codes.capacity() +
                                       ts.values.capacity() * sizeof(double) +
                                       ts.runs.capacity() * sizeof(CandidateRun) +
                                       ts.contacts.capacity() * sizeof(RawContact) + sizeof(ThreadState));
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
    for (int k = 0; k < 3; ++k) {
        const double lo = std::min(std::min(a[k], b[k]), std::min(c[k], d[k]));
        const double hi = std::max(std::max(a[k], b[k]), std::max(c[k], d[k]));
        // The same expressions as the vertex table's (p · (1/l), floor): monotone, so a vertex in the box has
        // its cell in [c0, c1]. Float box relative to the origin: rounding is monotone too, never a false reject.
        c0[k] = floor_to_int(lo * inv_cell);
        c1[k] = floor_to_int(hi * inv_cell);
        q.lo[k] = static_cast<float>(lo - origin[k]);
        q.hi[k] = static_cast<float>(hi - origin[k]);
    }
    for (int k = 0; k < 4; ++k) q.own[k] = tv[k];
    const std::int64_t nx = std::int64_t{c1[0]} - c0[0] + 1, ny = std::int64_t{c1[1]} - c0[1] + 1,
                       nz = std::int64_t{c1[2]} - c0[2] + 1;
    const bool column = params.hash == HashFunction::column;
    if ((column ? nx * ny : nx * ny * nz) > max_cells_per_tet) {
        if (!ts.too_many_cells) ts.too_many_cells_tet = t;
        ts.too_many_cells = true;
        return;
    }
    if (with_stats) ts.counters.cells += nx * ny * nz;

    const std::int32_t run_begin = static_cast<std::int32_t>(ts.used);
    // Table 0 holds the moving vertices, table 1 the static ones: static tets never look at table 1.
    const int num_tables =
        any_static && !flags.is_static[static_cast<std::size_t>(tet_object[static_cast<std::size_t>(t)])] ? 2 : 1;
    detail::ScanCounters sc;
    for (int ti = 0; ti < num_tables; ++ti) {
        const VertexTable& table = tables[ti];
        if (table.size() == 0) continue;
        const TableModulus& mod = table.modulus();
        const std::int32_t* start = table.start.data();
        // Bucket ranges collected in a fixed local array and scanned in batches (no per-range call).
        constexpr int max_ranges = 64;
        detail::ScanRange ranges[max_ranges];
        int nr = 0;
        std::size_t total = 0;
        auto flush = [&]() {
            if (nr == 0) return;
            const std::size_t need = ts.used + total;
            if (ts.candidates.size() < need) ts.candidates.resize(need + need / 4 + 64);
            ts.used += static_cast<std::size_t>(
                detail::scan_ranges(table, ranges, nr, q, ts.candidates.data() + ts.used, sc, with_stats));
            nr = 0;
            total = 0;
        };
        auto add = [&](std::int32_t begin, std::int32_t end, std::int32_t x, std::int32_t y, std::int32_t z0,
                       std::int32_t z1) {
            if (begin >= end) return;
            ranges[nr++] = {begin, end, x, y, z0, z1};
            total += static_cast<std::size_t>(end - begin);
            if (nr == max_ranges) flush();
        };
        if (column && mod.pow2 && static_cast<std::uint64_t>(nz) < mod.n) {
            // The common case: one contiguous range per column unless it wraps around the table's end.
            const std::uint64_t mask = mod.mask;
            const std::uint64_t zoff = static_cast<std::uint64_t>(static_cast<std::int64_t>(c0[2]));
            for (std::int32_t x = c0[0]; x <= c1[0]; ++x)
                for (std::int32_t y = c0[1]; y <= c1[1]; ++y) {
                    const std::uint64_t b0 = (column_mix(x, y) + zoff) & mask;
                    const std::uint64_t e = b0 + static_cast<std::uint64_t>(nz);
                    if (e <= mod.n) {
                        add(start[b0], start[e], x, y, c0[2], c1[2]);
                    } else {
                        add(start[b0], start[mod.n], x, y, c0[2], c1[2]);
                        add(start[0], start[e - mod.n], x, y, c0[2], c1[2]);
                    }
                }
        } else {
            for (std::int32_t x = c0[0]; x <= c1[0]; ++x)
                for (std::int32_t y = c0[1]; y <= c1[1]; ++y) {
                    if (column) {
                        const std::uint64_t h = column_mix(x, y);
                        if (static_cast<std::uint64_t>(nz) >= mod.n) {
                            add(0, table.size(), x, y, c0[2], c1[2]);
                        } else {
                            const std::uint64_t b0 = mod.column_bucket(h, c0[2]);
                            const std::uint64_t b1 = b0 + static_cast<std::uint64_t>(nz) - 1;
                            if (b1 < mod.n) {
                                add(start[b0], start[b1 + 1], x, y, c0[2], c1[2]);
                            } else {
                                add(start[b0], start[mod.n], x, y, c0[2], c1[2]);
                                add(start[0], start[b1 - mod.n + 1], x, y, c0[2], c1[2]);
                            }
                        }
                    } else {
                        for (std::int32_t z = c0[2]; z <= c1[2]; ++z) {
                            const std::uint64_t bk = mod.reduce(teschner_hash(x, y, z));
                            add(start[bk], start[bk + 1], x, y, z, z);
                        }
                    }
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
    const std::int32_t run_end = static_cast<std::int32_t>(ts.used);
    if (run_end > run_begin) ts.runs.push_back({t, run_begin, run_end});
}

// Stage 2 for up to 8 consecutive tets at once (column hash, power-of-two table, no static objects, no
// statistics): the columns of the block's cell box are looked up once and each of their entries is tested
// against the eight tet boxes in one SIMD compare. Consecutive tets of a mesh are mostly neighbours, so the
// block's box is much smaller than the sum of the eight tets' cell boxes (scenario 5: about half as many
// entries scanned and a quarter of the column lookups). Falls back to one tet at a time when the block's
// box is not smaller than the sum of the tets' boxes (tets far apart in the ordering).
void DetectorImpl::stage_block(ThreadState& ts, const Index* ids, int count, const double* P)
{
    alignas(32) detail::BlockQuery q;
    std::int32_t b0[3] = {std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max(),
                          std::numeric_limits<std::int32_t>::max()};
    std::int32_t b1[3] = {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::min(),
                          std::numeric_limits<std::int32_t>::min()};
    std::int64_t sum_cells = 0;
    for (int k = 0; k < 8; ++k) {
        if (k >= count) {
            for (int a = 0; a < 3; ++a) {
                q.lo[a][k] = std::numeric_limits<float>::infinity();
                q.hi[a][k] = -std::numeric_limits<float>::infinity();
            }
            for (int j = 0; j < 4; ++j) q.own[j][k] = -1;
            continue;
        }
        const Index* tv = tets_sorted.data() + 4 * static_cast<std::size_t>(ids - tet_order.data() + k);
        const double* a = P + 3 * static_cast<std::size_t>(tv[0]);
        const double* b = P + 3 * static_cast<std::size_t>(tv[1]);
        const double* c = P + 3 * static_cast<std::size_t>(tv[2]);
        const double* d = P + 3 * static_cast<std::size_t>(tv[3]);
        std::int64_t cells = 1;
        for (int ax = 0; ax < 3; ++ax) {
            const double lo = std::min(std::min(a[ax], b[ax]), std::min(c[ax], d[ax]));
            const double hi = std::max(std::max(a[ax], b[ax]), std::max(c[ax], d[ax]));
            const std::int32_t l = floor_to_int(lo * inv_cell), h = floor_to_int(hi * inv_cell);
            b0[ax] = std::min(b0[ax], l);
            b1[ax] = std::max(b1[ax], h);
            cells *= std::int64_t{h} - l + 1;
            q.lo[ax][k] = static_cast<float>(lo - origin[ax]);
            q.hi[ax][k] = static_cast<float>(hi - origin[ax]);
        }
        sum_cells += cells;
        for (int j = 0; j < 4; ++j) q.own[j][k] = tv[j];
    }
    const std::int64_t nx = std::int64_t{b1[0]} - b0[0] + 1, ny = std::int64_t{b1[1]} - b0[1] + 1,
                       nz = std::int64_t{b1[2]} - b0[2] + 1;
    const VertexTable& table = tables[0];
    const TableModulus& mod = table.modulus();
    if (nx * ny * nz > sum_cells || static_cast<std::uint64_t>(nz) >= mod.n || table.size() == 0) {
        for (int k = 0; k < count; ++k) stage_tets(ts, ids[k], P, false);
        return;
    }
    const std::int32_t* start = table.start.data();
    constexpr int max_ranges = 64;
    detail::ScanRange ranges[max_ranges];
    int nr = 0;
    std::size_t total = 0, nhits = 0;
    auto flush = [&]() {
        if (nr == 0) return;
        const std::size_t need = nhits + total + 1;
        if (ts.hits.size() < need) ts.hits.resize(need + need / 4 + 64);
        nhits += static_cast<std::size_t>(detail::scan_block(table, ranges, nr, q, ts.hits.data() + nhits));
        nr = 0;
        total = 0;
    };
    auto add = [&](std::int32_t begin, std::int32_t end, std::int32_t x, std::int32_t y) {
        if (begin >= end) return;
        ranges[nr++] = {begin, end, x, y, b0[2], b1[2]};
        total += static_cast<std::size_t>(end - begin);
        if (nr == max_ranges) flush();
    };
    const std::uint64_t mask = mod.mask;
    const std::uint64_t zoff = static_cast<std::uint64_t>(static_cast<std::int64_t>(b0[2]));
    for (std::int32_t x = b0[0]; x <= b1[0]; ++x)
        for (std::int32_t y = b0[1]; y <= b1[1]; ++y) {
            const std::uint64_t s0 = (column_mix(x, y) + zoff) & mask;
            const std::uint64_t e = s0 + static_cast<std::uint64_t>(nz);
            if (e <= mod.n) {
                add(start[s0], start[e], x, y);
            } else {
                add(start[s0], start[mod.n], x, y);
                add(start[0], start[e - mod.n], x, y);
            }
        }
    flush();
    if (nhits == 0) return;
    // Hits (entry-major, a lane mask each) → one candidate run per tet, in tet order.
    std::int32_t offset[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    const detail::BlockHit* hits = ts.hits.data();
    for (std::size_t h = 0; h < nhits; ++h)
        for (int lanes = hits[h].lanes; lanes; lanes &= lanes - 1) ++offset[__builtin_ctz(static_cast<unsigned>(lanes)) + 1];
    for (int k = 0; k < 8; ++k) offset[k + 1] += offset[k];
    const std::size_t need = ts.used + static_cast<std::size_t>(offset[8]);
    if (ts.candidates.size() < need) ts.candidates.resize(need + need / 4 + 64);
    Index* cand = ts.candidates.data() + ts.used;
    std::int32_t fill[8];
    for (int k = 0; k < 8; ++k) fill[k] = offset[k];
    for (std::size_t h = 0; h < nhits; ++h)
        for (int lanes = hits[h].lanes; lanes; lanes &= lanes - 1)
            cand[fill[__builtin_ctz(static_cast<unsigned>(lanes))]++] = hits[h].vertex;
    const auto base = static_cast<std::int32_t>(ts.used);
    for (int k = 0; k < count; ++k)
        if (offset[k + 1] > offset[k]) ts.runs.push_back({ids[k], base + offset[k], base + offset[k + 1]});
    ts.used = need;
}

// Stage 3 over a thread's candidate runs: face planes per tet (only tets with candidates), filtered
// plane tests for all candidates of the tet at once (AVX2 where available), exact orientation only where
// the filter cannot decide.
void DetectorImpl::stage_inside(ThreadState& ts, const double* P)
{
    for (const CandidateRun& run : ts.runs) {
        const Index t = run.tet;
        const Index* tv = tets.data() + 4 * static_cast<std::size_t>(t);
        const double* A = P + 3 * static_cast<std::size_t>(tv[0]);
        const double* B = P + 3 * static_cast<std::size_t>(tv[1]);
        const double* C = P + 3 * static_cast<std::size_t>(tv[2]);
        const double* D = P + 3 * static_cast<std::size_t>(tv[3]);
        const Index to = tet_object[static_cast<std::size_t>(t)];
        Index* cand = ts.candidates.data() + run.begin;
        std::int32_t count = run.end - run.begin;
        if (any_self_off && !flags.self_collision[static_cast<std::size_t>(to)]) {
            std::int32_t kept = 0;
            for (std::int32_t j = 0; j < count; ++j)
                if (vertex_object[static_cast<std::size_t>(cand[j])] != to) cand[kept++] = cand[j];
            count = kept;
            if (count == 0) continue;
        }
        const predicates::Orientation o = predicates::orient3d(A, B, C, D);
        ts.counters.exact += o.exact;
        if (o.sign == 0) continue;
        const double s = o.sign;
        // Face i: p replaces vertex i; value = n_i · (p − r_i) (the orient3d evaluation order, so Shewchuk's
        // bound holds); m_i are the permanent weights of the bound. The sign of the tet is folded into n_i.
        detail::FacePlanes f;
        auto face = [&](int i, const double* ref, const double* u, const double* w) {
            const double ux = u[0] - ref[0], uy = u[1] - ref[1], uz = u[2] - ref[2];
            const double wx = w[0] - ref[0], wy = w[1] - ref[1], wz = w[2] - ref[2];
            f.nx[i] = s * (uy * wz - uz * wy);
            f.ny[i] = s * (uz * wx - ux * wz);
            f.nz[i] = s * (ux * wy - uy * wx);
            f.mx[i] = std::fabs(uy * wz) + std::fabs(uz * wy);
            f.my[i] = std::fabs(uz * wx) + std::fabs(ux * wz);
            f.mz[i] = std::fabs(ux * wy) + std::fabs(uy * wx);
            f.rx[i] = ref[0];
            f.ry[i] = ref[1];
            f.rz[i] = ref[2];
        };
        face(0, D, C, B);   // orient(p,b,c,d) = (p−d)·((c−d)×(b−d))
        face(1, D, A, C);   // orient(a,p,c,d) = (p−d)·((a−d)×(c−d))
        face(2, D, B, A);   // orient(a,b,p,d) = (p−d)·((b−d)×(a−d))
        face(3, A, B, C);   // orient(a,b,c,p) = (p−a)·((b−a)×(c−a))
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
                    case 0: e = predicates::orient3d_exact(p, B, C, D); break;
                    case 1: e = predicates::orient3d_exact(A, p, C, D); break;
                    case 2: e = predicates::orient3d_exact(A, B, p, D); break;
                    default: e = predicates::orient3d_exact(A, B, C, p); break;
                    }
                    ++ts.counters.exact;
                    if (e.sign * o.sign < 0) outside = true;
                    val[i] = e.value * s;
                }
                if (outside) continue;
            }
            const double sum = val[0] + val[1] + val[2] + val[3];
            RawContact rc;
            rc.vertex = v;
            rc.tet = t;
            for (int i = 0; i < 4; ++i) rc.bary[i] = val[i] == 0.0 ? 0.0 : val[i] / sum;
            ts.contacts.push_back(rc);
        }
    }
}

const std::vector<Contact>& DetectorImpl::detect(const PositionsRef& positions, DetectStats* stats)
{
    const auto t_start = Clock::now();
    if (positions.rows() != num_vertices)
        throw Error("positions has " + std::to_string(positions.rows()) + " rows, expected " +
                    std::to_string(num_vertices) + " (the number of vertices given to set_topology)");
    if (!prepared) prepare(positions);
    const int T = resolve_threads(params.threads);
    if (static_cast<int>(threads.size()) != T) threads.resize(static_cast<std::size_t>(T));
    const double* P = positions.data();

    // Stage 1: moving vertices.
    const Index* ids = any_static ? dynamic_ids.data() : nullptr;
    const Index count = static_cast<Index>(dynamic_ids.size());
    if (!tables[0].build(P, ids, count, cell_size, origin, table_sizes[0], params.hash, T))
        diagnose_build_failure(positions, ids, count);
    const double ms_vertices = ms_since(t_start);

    // Stages 2 and 3, parallel over tets; each thread then tests its own candidates.
    const Index m = static_cast<Index>(tets.size() / 4);
    const bool with_stats = stats != nullptr;
    // The block path (eight tets per scan) where it applies; statistics count per tet, so they use the other.
    // Environment TETHASH_BLOCKS=0 turns it off (for measuring one path against the other).
    static const bool blocks_allowed = [] {
        const char* e = std::getenv("TETHASH_BLOCKS");
        return !(e && std::strcmp(e, "0") == 0);
    }();
    const bool use_blocks = blocks_allowed && !with_stats && !any_static && params.hash == HashFunction::column &&
                            tables[0].modulus().pow2;
    for (ThreadState& ts : threads) {
        ts.used = 0;
        ts.runs.clear();
        ts.contacts.clear();
        ts.counters = Counters{};
        ts.too_many_cells = false;
    }
#pragma omp parallel num_threads(T)
    {
#ifdef TETHASH_HAVE_OPENMP
        ThreadState& ts = threads[static_cast<std::size_t>(omp_get_thread_num())];
#else
        ThreadState& ts = threads[0];
#endif
        const auto t0 = Clock::now();
        if (use_blocks) {
            const Index blocks = (m + 7) / 8;
#pragma omp for schedule(dynamic, 32) nowait
            for (Index bi = 0; bi < blocks; ++bi)
                stage_block(ts, tet_order.data() + 8 * bi, static_cast<int>(std::min<Index>(8, m - 8 * bi)), P);
        } else {
#pragma omp for schedule(dynamic, 256) nowait
            for (Index t = 0; t < m; ++t) stage_tets(ts, t, P, with_stats);
        }
        ts.ms_tets = ms_since(t0);
        const auto t1 = Clock::now();
        stage_inside(ts, P);
        ts.ms_inside = ms_since(t1);
    }
    for (const ThreadState& ts : threads)
        if (ts.too_many_cells)
            throw Error("cell size " + std::to_string(cell_size) + " is too small: tet " +
                        std::to_string(ts.too_many_cells_tet) + " would visit more than 2^24 cells; use a larger cell size");

    // Merge: counting sort by vertex (stable), then by tet within each vertex.
    const auto t_sort = Clock::now();
    vertex_counts.assign(static_cast<std::size_t>(num_vertices) + 1, 0);
    std::size_t total = 0;
    for (const ThreadState& ts : threads) {
        total += ts.contacts.size();
        for (const RawContact& rc : ts.contacts) ++vertex_counts[static_cast<std::size_t>(rc.vertex) + 1];
    }
    for (Index v = 0; v < num_vertices; ++v) vertex_counts[v + 1] += vertex_counts[v];
    contacts.resize(total);
    for (const ThreadState& ts : threads)
        for (const RawContact& rc : ts.contacts) {
            Contact& c = contacts[static_cast<std::size_t>(vertex_counts[rc.vertex]++)];
            c.vertex = rc.vertex;
            c.tet = rc.tet;
            c.vertex_object = vertex_object[static_cast<std::size_t>(rc.vertex)];
            c.tet_object = tet_object[static_cast<std::size_t>(rc.tet)];
            for (int k = 0; k < 4; ++k) c.bary[k] = rc.bary[k];
            c.depth = std::numeric_limits<double>::quiet_NaN();
            c.direction[0] = c.direction[1] = c.direction[2] = 0;
        }
    {
        std::int32_t begin = 0;
        for (Index v = 0; v < num_vertices; ++v) {
            const std::int32_t end = vertex_counts[v];
            if (end - begin > 1)
                std::sort(contacts.begin() + begin, contacts.begin() + end,
                          [](const Contact& x, const Contact& y) { return x.tet < y.tet; });
            begin = end;
        }
    }
    const double ms_sort = ms_since(t_sort);

    if (stats) {
        Counters sum;
        DetectStats& s = *stats;
        s = DetectStats{};
        s.ms_vertices = ms_vertices;
        for (const ThreadState& ts : threads) {
            sum.add(ts.counters);
            s.ms_tets = std::max(s.ms_tets, ts.ms_tets);
            s.ms_inside = std::max(s.ms_inside, ts.ms_inside);
        }
        s.ms_sort = ms_sort;
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
        s.ms_total = ms_since(t_start);
    }
    return contacts;
}

// ---- public wrappers -------------------------------------------------------------------------------

namespace {
void validate_params(const DetectParams& p)
{
    using Mode = DetectParams::CellSizeMode;
    if (p.cell_size_mode == Mode::absolute && !(p.cell_size > 0 && std::isfinite(p.cell_size)))
        throw Error("cell_size must be positive and finite, got " + std::to_string(p.cell_size));
    if (p.cell_size_mode == Mode::factor_of_mean_edge && !(p.cell_size > 0 && std::isfinite(p.cell_size)))
        throw Error("cell_size factor must be positive and finite, got " + std::to_string(p.cell_size));
    if (p.table_size < 0)
        throw Error("table_size must be ≥ 1 (or 0 for automatic), got " + std::to_string(p.table_size));
    if (p.table_size > max_table_size)
        throw Error("table_size " + std::to_string(p.table_size) + " is too large (at most " +
                    std::to_string(max_table_size) + ")");
    if (p.threads < 0) throw Error("threads must be ≥ 0 (0 = all), got " + std::to_string(p.threads));
    if (p.hash != HashFunction::teschner && p.hash != HashFunction::column)
        throw Error("hash function out of range: " + std::to_string(static_cast<int>(p.hash)));
}
} // namespace

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
    validate_params(params);
    m_impl->params = params;
    m_impl->prepared = false;
}

const DetectParams& Detector::params() const { return m_impl->params; }

void Detector::set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                            std::span<const Index> tet_object, std::span<const ObjectOptions> objects)
{
    detail::check_topology(tets, num_vertices, vertex_object, tet_object);
    DetectorImpl& d = *m_impl;
    const Index m = static_cast<Index>(tets.rows());
    d.num_vertices = num_vertices;
    d.tets.resize(4 * static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t)
        for (int k = 0; k < 4; ++k) d.tets[4 * static_cast<std::size_t>(t) + k] = tets(t, k);
    d.vertex_object.assign(vertex_object.begin(), vertex_object.end());
    if (d.vertex_object.empty()) d.vertex_object.assign(static_cast<std::size_t>(num_vertices), 0);
    d.tet_object.assign(tet_object.begin(), tet_object.end());
    if (d.tet_object.empty()) d.tet_object.assign(static_cast<std::size_t>(m), 0);
    d.flags = detail::object_flags(vertex_object, tet_object, objects);
    d.any_static = std::any_of(d.flags.is_static.begin(), d.flags.is_static.end(), [](unsigned char c) { return c; });
    d.any_self_off =
        std::any_of(d.flags.self_collision.begin(), d.flags.self_collision.end(), [](unsigned char c) { return !c; });
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

std::vector<Contact>& Detector::contacts() { return m_impl->contacts; }

} // namespace tethash
