#pragma once
// OpenMP team helpers (private header): the calling thread's place in the current team (1 thread outside any
// parallel region or without OpenMP) and the parallel prefix sum of a counting sort split over the team.
#include <cstdint>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash::detail {

inline int team_rank()
{
#ifdef TETHASH_HAVE_OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

inline int team_size()
{
#ifdef TETHASH_HAVE_OPENMP
    return omp_get_num_threads();
#else
    return 1;
#endif
}

inline void team_barrier()
{
#ifdef TETHASH_HAVE_OPENMP
#pragma omp barrier
#endif
}

/// [begin, end) of part `part` of `parts` equal parts of [0, n).
inline void team_split(std::int64_t n, int part, int parts, std::int64_t& begin, std::int64_t& end)
{
    begin = n * part / parts;
    end = n * (part + 1) / parts;
}

/// Counting-sort offsets computed by the whole team; every thread of the team calls it (it contains barriers).
/// On entry hist[p][b] (p < parts, b < n) counts the keys b of part p of the input (the parts contiguous and in
/// input order). On return hist[p][b] is where part p's first key b goes in the stably sorted output, and
/// start[b] (b ≤ n) the first index of key b (start[n] = total). `partial`: room for team_size() + 1 values.
/// Buckets are split over the team; the result is the same for any team size.
inline void team_counting_offsets(std::int32_t* const* hist, int parts, std::int64_t n, std::int32_t* start,
                                  std::int64_t* partial)
{
    const int rank = team_rank(), size = team_size();
    std::int64_t b0, b1;
    team_split(n, rank, size, b0, b1);
    std::int64_t sum = 0;
    for (int p = 0; p < parts; ++p) {
        const std::int32_t* h = hist[p];
        for (std::int64_t b = b0; b < b1; ++b) sum += h[b];
    }
    partial[rank] = sum;
    team_barrier();
    std::int64_t base = 0;
    for (int r = 0; r < rank; ++r) base += partial[r];
    if (parts == 1) {
        std::int32_t* h = hist[0];
        for (std::int64_t b = b0; b < b1; ++b) {
            const std::int32_t c = h[b];
            start[b] = h[b] = static_cast<std::int32_t>(base);
            base += c;
        }
    } else {
        for (std::int64_t b = b0; b < b1; ++b) {
            start[b] = static_cast<std::int32_t>(base);
            for (int p = 0; p < parts; ++p) {
                const std::int32_t c = hist[p][b];
                hist[p][b] = static_cast<std::int32_t>(base);
                base += c;
            }
        }
    }
    if (rank == size - 1) start[n] = static_cast<std::int32_t>(base);
    team_barrier();
}

} // namespace tethash::detail
