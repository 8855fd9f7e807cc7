#pragma once
// OpenMP team helpers (private header): the calling thread's place in the current team (1 thread outside any
// parallel region or without OpenMP), a barrier, an even split of a range.
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

} // namespace tethash::detail
