// Stage 1: counting sort of the vertices by bucket into one contiguous structure of arrays.
#include "tethash/hash_grid.hpp"

#include <cmath>
#include <cstring>
#include <limits>

#ifdef TETHASH_HAVE_OPENMP
#include <omp.h>
#endif

namespace tethash {

std::int64_t next_prime(std::int64_t n)
{
    if (n <= 2) return 2;
    for (std::int64_t c = n | 1;; c += 2) {
        bool prime = true;
        for (std::int64_t d = 3; d * d <= c; d += 2)
            if (c % d == 0) {
                prime = false;
                break;
            }
        if (prime) return c;
    }
}

std::int64_t auto_table_size(HashFunction hash, std::int64_t vertices)
{
    const std::int64_t want = std::max<std::int64_t>(2 * vertices, 1);
    if (hash == HashFunction::teschner) return std::min(next_prime(want), max_table_size);
    std::int64_t n = 1;
    while (n < want && n < max_table_size) n <<= 1;
    return n;
}

std::int64_t VertexTable::memory_bytes() const
{
    return static_cast<std::int64_t>(x.capacity() * 3 * sizeof(float) + id.capacity() * sizeof(std::int32_t) +
                                     key.capacity() * sizeof(std::uint32_t) + start.capacity() * sizeof(std::int32_t) +
                                     m_bucket.capacity() * 4 + m_key.capacity() * 4);
}

bool VertexTable::build(const double* positions, const Index* ids, Index count, double cell_size,
                        const double origin[3], std::int64_t table_size, HashFunction hash, int threads)
{
    m_mod = TableModulus(static_cast<std::uint64_t>(table_size));
    m_count = count;
    const std::size_t padded = static_cast<std::size_t>(count) + 8;
    if (x.size() != padded) {
        for (auto* v : {&x, &y, &z}) v->assign(padded, std::numeric_limits<float>::quiet_NaN());
        id.assign(padded, std::numeric_limits<std::int32_t>::min());
        key.assign(padded, 0);
    }
    m_bucket.resize(count);
    m_key.resize(count);
    start.assign(static_cast<std::size_t>(table_size) + 1, 0);

    const double inv = 1.0 / cell_size;
    const double ox = origin[0], oy = origin[1], oz = origin[2];
    const TableModulus mod = m_mod;
    int bad = 0;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(| : bad) if (count > 20000)
    for (Index i = 0; i < count; ++i) {
        const Index v = ids ? ids[i] : i;
        const double* p = positions + 3 * static_cast<std::size_t>(v);
        const double sx = p[0] * inv, sy = p[1] * inv, sz = p[2] * inv;
        // NaN fails every comparison: caught here too.
        if (!(std::fabs(sx) < max_cell_coordinate && std::fabs(sy) < max_cell_coordinate &&
              std::fabs(sz) < max_cell_coordinate)) {
            bad = 1;
            continue;
        }
        const std::int32_t ix = floor_to_int(sx), iy = floor_to_int(sy), iz = floor_to_int(sz);
        m_key[i] = cell_key(ix, iy, iz);
        m_bucket[i] = static_cast<std::uint32_t>(hash == HashFunction::column
                                                     ? mod.column_bucket(column_mix(ix, iy), iz)
                                                     : mod.reduce(teschner_hash(ix, iy, iz)));
    }
    if (bad) return false;

    // Counting sort, stable in input order (deterministic whatever the thread count).
    std::int32_t* s = start.data();
    for (Index i = 0; i < count; ++i) ++s[m_bucket[i] + 1];
    for (std::int64_t b = 0; b < table_size; ++b) s[b + 1] += s[b];
    for (Index i = 0; i < count; ++i) {
        const std::int32_t k = s[m_bucket[i]]++;
        const Index v = ids ? ids[i] : i;
        const double* p = positions + 3 * static_cast<std::size_t>(v);
        x[k] = static_cast<float>(p[0] - ox);
        y[k] = static_cast<float>(p[1] - oy);
        z[k] = static_cast<float>(p[2] - oz);
        id[k] = v;
        key[k] = m_key[i];
    }
    // start[b] now holds the end of bucket b: shift right by one.
    std::memmove(s + 1, s, static_cast<std::size_t>(table_size) * sizeof(std::int32_t));
    s[0] = 0;
    return true;
}

} // namespace tethash
