// Candidate reuse of the hash detector (the skin, docs/detection.md): whether the kept candidates still hold every
// contact, keeping them after a full detection, and stage 3 alone over them.
#include "../team.hpp"
#include "detector_impl.hpp"
#include "tethash/predicates.hpp"

#include <algorithm>
#include <cmath>

namespace tethash {

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
