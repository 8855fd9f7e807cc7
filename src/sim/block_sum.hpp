#pragma once
// Sums over blocks of a fixed size (private to tethash::sim): the same bits at any thread count.

#include "tethash/mesh.hpp"

#include <algorithm>
#include <vector>

namespace tethash::sim::detail {

/// Sums f(begin, end) over [0, n) in blocks of 4,096, the blocks split over `threads`, each block's partial kept
/// and the partials added (`T::operator+=`) in block order: the same result whatever the number of threads.
template <class T, class F> T block_sum(Index n, int threads, F&& f)
{
    (void)threads; // without OpenMP every block runs on the calling thread
    constexpr Index block = 4096;
    const Index blocks = (n + block - 1) / block;
    std::vector<T> part(static_cast<size_t>(blocks));
#ifdef TETHASH_HAVE_OPENMP
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && blocks > 1)
#endif
    for (Index b = 0; b < blocks; ++b)
        part[static_cast<size_t>(b)] = f(b * block, std::min(n, (b + 1) * block));
    T sum{};
    for (const T& p : part)
        sum += p;
    return sum;
}

} // namespace tethash::sim::detail
