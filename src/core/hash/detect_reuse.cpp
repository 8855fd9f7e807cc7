// Candidate reuse of the hash detector (the skin, docs/detection.md): whether the kept candidates still hold every
// contact, keeping them after a full detection, and stage 3 alone over them.
#include "../team.hpp"
#include "detector_impl.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tethash {

// Skin: true when the moving vertices' displacements since the remembered positions (the last full detection) span
// less than 2 × `limit` per axis, with 0 among them when the scene has static vertices (those never move). The
// contacts do not change under a common translation, so what must stay below `limit` is each displacement minus the
// centre of that span (reuse_limit < skin / 2 allows reuse: docs/detection.md, "why it is exact"); a body falling
// or thrown as a whole keeps its candidates. A non-finite coordinate counts as moved too far (the full detection
// then reports it). Blocks of 1,024 vertices with an early exit; parallel over the team for big scenes only (a
// region costs more than checking 20,000 vertices).
bool DetectorImpl::moved_less_than(const double* P, int T, double limit) const
{
    const double span = 2.0 * limit;
    const double* R = reference.data();
    const std::int64_t n = static_cast<std::int64_t>(dynamic_ids.size());
    const Index* ids = dynamic_ids.data();
    constexpr std::int64_t block = 1024;
    const std::int64_t blocks = (n + block - 1) / block;
    // Static vertices put 0 among the displacements; otherwise the span starts empty.
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double start_lo = any_static ? 0.0 : inf, start_hi = any_static ? 0.0 : -inf;
    double lo0 = start_lo, lo1 = start_lo, lo2 = start_lo, hi0 = start_hi, hi1 = start_hi, hi2 = start_hi;
    int far = 0;
#pragma omp parallel for schedule(static) reduction(|                                                                  \
                                                    : far) reduction(min                                               \
                                                                     : lo0, lo1, lo2) reduction(max                    \
                                                                                                : hi0, hi1, hi2)       \
    num_threads(T) if (T > 1 && n >= 65536)
    for (std::int64_t b = 0; b < blocks; ++b) {
        if (far) continue;
        const std::int64_t i0 = b * block, i1 = std::min(n, i0 + block);
        double lo[3] = {lo0, lo1, lo2}, hi[3] = {hi0, hi1, hi2};
        int bad = 0;
        for (std::int64_t i = i0; i < i1; ++i) {
            const double* p = P + 3 * static_cast<std::size_t>(any_static ? ids[i] : static_cast<Index>(i));
            const double* r = R + 3 * i;
            for (int k = 0; k < 3; ++k) {
                const double d = p[k] - r[k];
                bad |= !(std::fabs(d) < inf); // NaN or infinite
                lo[k] = std::min(lo[k], d);
                hi[k] = std::max(hi[k], d);
            }
        }
        // This thread's span so far is part of the whole: when it is already too wide, so is the whole.
        for (int k = 0; k < 3; ++k)
            bad |= !(hi[k] - lo[k] < span);
        lo0 = lo[0], lo1 = lo[1], lo2 = lo[2], hi0 = hi[0], hi1 = hi[1], hi2 = hi[2];
        far |= bad;
    }
    return !far && hi0 - lo0 < span && hi1 - lo1 < span && hi2 - lo2 < span;
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

} // namespace tethash
