// Stages 2 and 3 of the hash detector for one tet and one thread's candidates: the tet's box → bucket ranges →
// candidate vertices (SIMD scan), then the closed inside test by lazily built face planes with a filtered exact
// fallback; and each thread's radix sort of its contacts.
#include "../simd.hpp"
#include "detector_impl.hpp"
#include "scan.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cstring>

namespace tethash {

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
    finish_run(ts, t, run_begin);
}

__attribute__((always_inline)) inline void DetectorImpl::finish_run(ThreadState& ts, Index t, std::int32_t run_begin)
{
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

namespace {
// The lean path pays with the column kernel of the AVX2 scan (no z test); the scalar kernels keep the general path.
const bool avx2_scan = detail::avx2_kernels();
} // namespace

bool DetectorImpl::lean_stage_tets(bool with_stats) const
{
    if (!avx2_scan || with_stats || params.hash != HashFunction::column) return false;
    for (const VertexTable& table : tables)
        if (table.size() > 0 && !table.modulus().pow2) return false;
    return true;
}

// Stage 2 for one tet in the common case (column hash, power-of-two tables, no statistics, AVX2; run only where
// lean_stage_tets() says so): the box and its cells as in stage_tets, one contiguous range per column (two where the
// z-run wraps around the table), the scan kernel (column_scan_kernel: no z test) called directly, no per-tet branch
// on statistics, hash or table kind. Tets outside the common case (cell boxes too big for the keys or the range
// array, a z-run as long as a table) go to stage_tets. (The box, cells and float box in the lanes (x, y, z, -) of
// AVX2 registers: 10 % fewer instructions, but the function compiled for AVX2 measured 3 % slower on the hand; the
// candidate buffer sized by the table instead of the ranges' lengths: 4 % fewer, 1.5 % slower on the hand.)
void DetectorImpl::stage_tets_lean(ThreadState& ts, Index t, const double* P, detail::ScanKernel scan)
{
    const Index* tv = tets.data() + 4 * static_cast<std::size_t>(t);
    const double* pa = P + 3 * static_cast<std::size_t>(tv[0]);
    const double* pb = P + 3 * static_cast<std::size_t>(tv[1]);
    const double* pc = P + 3 * static_cast<std::size_t>(tv[2]);
    const double* pd = P + 3 * static_cast<std::size_t>(tv[3]);
    detail::ScanQuery q;
    std::int32_t c0s[3];
    std::int64_t ns[3]; // up to 2^31 + 1 cells at the guarded range's ends
    const double limit = max_cell_coordinate * cell_size;
    for (int k = 0; k < 3; ++k) {
        const double lo = std::max(std::min(std::min(pa[k], pb[k]), std::min(pc[k], pd[k])) - skin, -limit);
        const double hi = std::min(std::max(std::max(pa[k], pb[k]), std::max(pc[k], pd[k])) + skin, limit);
        c0s[k] = floor_to_int(lo * inv_cell);
        ns[k] = std::int64_t{floor_to_int(hi * inv_cell)} - c0s[k] + 1;
        q.lo[k] = static_cast<float>(lo - origin[k]);
        q.hi[k] = static_cast<float>(hi - origin[k]);
    }
    std::memcpy(q.own, tv, sizeof q.own);
    const std::int64_t nx = ns[0], ny = ns[1], nz = ns[2];
    constexpr int max_ranges = 64;
    // Outside the common case: the general path (which also reports a cell box too big for the grid).
    if (nx > key_exact_xy || ny > key_exact_xy || nz > key_exact_z || 2 * nx * ny > max_ranges) {
        stage_tets(ts, t, P, false);
        return;
    }
    const std::int32_t run_begin = static_cast<std::int32_t>(ts.used);
    const int num_tables =
        any_static && !flags.is_static[static_cast<std::size_t>(tet_object[static_cast<std::size_t>(t)])] ? 2 : 1;
    const std::int32_t x0 = c0s[0], y0 = c0s[1], y1 = static_cast<std::int32_t>(y0 + ny - 1);
    q.z0 = c0s[2];
    q.z1 = static_cast<std::int32_t>(c0s[2] + nz - 1);
    const std::uint64_t zoff = static_cast<std::uint64_t>(static_cast<std::int64_t>(c0s[2]));
    detail::ScanCounters unused;
    for (int ti = 0; ti < num_tables; ++ti) {
        const VertexTable& table = tables[ti];
        if (table.size() == 0) continue;
        const TableModulus& mod = table.modulus();
        if (static_cast<std::uint64_t>(nz) >= mod.n) { // a z-run that covers the table: the general path
            ts.used = static_cast<std::size_t>(run_begin);
            stage_tets(ts, t, P, false);
            return;
        }
        const std::int32_t* start = table.start.data();
        const std::uint64_t mask = mod.mask, n = mod.n;
        detail::ScanRange ranges[max_ranges];
        int nr = 0;
        std::size_t total = 0;
        std::int32_t x = x0, y = y0;
        for (std::int64_t j = nx * ny; j > 0; --j) {
            const std::uint64_t b0 = (column_mix(x, y) + zoff) & mask;
            const std::uint64_t e = b0 + static_cast<std::uint64_t>(nz);
            if (e <= n) [[likely]] {
                ranges[nr] = {start[b0], start[e], x, y};
                total += static_cast<std::size_t>(std::max(start[e] - start[b0], 0));
                nr += ranges[nr].begin < ranges[nr].end;
            } else {
                total += static_cast<std::size_t>(std::max(start[n] - start[b0], 0)) +
                         static_cast<std::size_t>(std::max(start[e - n] - start[0], 0));
                ranges[nr] = {start[b0], start[n], x, y};
                nr += ranges[nr].begin < ranges[nr].end;
                ranges[nr] = {start[0], start[e - n], x, y};
                nr += ranges[nr].begin < ranges[nr].end;
            }
            const bool wrap = y == y1;
            x += wrap;
            y = wrap ? y0 : y + 1;
        }
        if (nr == 0) continue;
        const std::size_t need = ts.used + total + 8; // 8: the kernel's slack
        if (ts.candidates.size() < need) ts.candidates.resize(need + need / 4 + 64);
        ts.used += static_cast<std::size_t>(scan(table, ranges, nr, q, ts.candidates.data() + ts.used, unused));
    }
    finish_run(ts, t, run_begin);
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
            ts.kept.resize(ts.codes.size());
        }
        const std::int32_t num_kept =
            detail::filter_candidates(f, P, cand, count, ts.values.data(), ts.codes.data(), ts.kept.data());
        ts.counters.inside_tests += count;
        for (std::int32_t k = 0; k < num_kept; ++k) {
            const int code = ts.codes[static_cast<std::size_t>(k)];
            const Index v = cand[ts.kept[static_cast<std::size_t>(k)]];
            double* val = ts.values.data() + 4 * static_cast<std::size_t>(k);
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

// Sorts a thread's contacts by (vertex, tet) without any synchronisation: they come out of stage 3 in increasing
// tet order (monotonic dynamic schedule, runs in order), so a stable LSD radix sort by vertex (11-bit digits) does
// it. The result is in ts.contacts.
void detail::sort_own_contacts(ThreadState& ts, Index num_vertices)
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

} // namespace tethash
