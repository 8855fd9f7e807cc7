// Stage 1: counting sort of the vertices by bucket into one contiguous structure of arrays.
#include "hash_grid.hpp"

#include "../team.hpp"

#include <algorithm>

#include <cmath>
#include <cstring>
#include <limits>

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
    while (n < want && n < max_table_size)
        n <<= 1;
    return n;
}

std::int64_t VertexTable::memory_bytes() const
{
    return static_cast<std::int64_t>(x.capacity() * 3 * sizeof(float) + id.capacity() * sizeof(std::int32_t) +
                                     key.capacity() * sizeof(std::uint32_t) + start.capacity() * sizeof(std::int32_t) +
                                     m_bucket.capacity() * 4 + m_key.capacity() * 4 + m_cursor.capacity() * 4);
}

namespace {
/// Fewest vertices per thread for which the team build splits the work (below: one thread builds, the others wait).
constexpr Index team_build_min_per_thread = 32768;
/// Most threads the team build splits over (each spare entry and cursor slot is per thread).
constexpr int team_build_max_parts = 16;
int build_parts(Index count, int size)
{
    return VertexTable::team_parts(count, size);
}
constexpr std::size_t padding = 8;
} // namespace

int VertexTable::team_parts(Index count, int threads)
{
    return static_cast<int>(
        std::clamp<Index>(count / team_build_min_per_thread, 1, std::min(threads, team_build_max_parts)));
}

void VertexTable::reserve(Index count, std::int64_t table_size, int threads)
{
    const std::size_t padded = static_cast<std::size_t>(count) + padding + team_build_max_parts;
    if (x.size() != padded) {
        for (auto* v : {&x, &y, &z})
            v->assign(padded, std::numeric_limits<float>::quiet_NaN());
        id.assign(padded, std::numeric_limits<std::int32_t>::min());
        key.assign(padded, 0);
    }
    m_bucket.resize(static_cast<std::size_t>(count));
    m_key.resize(static_cast<std::size_t>(count));
    start.resize(static_cast<std::size_t>(table_size) + 1);
    m_bad = 0;
    const int parts = build_parts(count, threads);
    if (parts > 1) m_cursor.resize(static_cast<std::size_t>(table_size) + 16 * static_cast<std::size_t>(parts));
}

bool VertexTable::build(const double* positions, const Index* ids, Index count, double cell_size,
                        const double origin[3], std::int64_t table_size, HashFunction hash, int threads)
{
    reserve(count, table_size, threads);
    bool ok = true;
    if (threads > 1 && build_parts(count, threads) > 1) {
#pragma omp parallel num_threads(threads)
        {
            const bool r = build_team(positions, ids, count, cell_size, origin, table_size, hash);
            if (detail::team_rank() == 0) ok = r;
        }
    } else {
        ok = build_team(positions, ids, count, cell_size, origin, table_size, hash);
    }
    return ok;
}

bool VertexTable::build_team(const double* positions, const Index* ids, Index count, double cell_size,
                             const double origin[3], std::int64_t table_size, HashFunction hash)
{
    const int rank = detail::team_rank(), size = detail::team_size();
    const int parts = build_parts(count, size);
    const TableModulus mod(static_cast<std::uint64_t>(table_size));
    const double inv = 1.0 / cell_size;
    const double ox = origin[0], oy = origin[1], oz = origin[2];
    if (rank == 0) {
        m_mod = mod;
        m_count = count;
    }
    // Cells and buckets of the vertices [i0, i1); true when one is out of range or not finite.
    auto cells = [&](std::int64_t i0, std::int64_t i1) {
        bool bad = false;
        for (std::int64_t i = i0; i < i1; ++i) {
            const Index v = ids ? ids[i] : static_cast<Index>(i);
            const double* p = positions + 3 * static_cast<std::size_t>(v);
            const double sx = p[0] * inv, sy = p[1] * inv, sz = p[2] * inv;
            // NaN fails every comparison: caught here too.
            if (!(std::fabs(sx) < max_cell_coordinate && std::fabs(sy) < max_cell_coordinate &&
                  std::fabs(sz) < max_cell_coordinate)) {
                bad = true;
                continue;
            }
            const std::int32_t ix = floor_to_int(sx), iy = floor_to_int(sy), iz = floor_to_int(sz);
            m_key[static_cast<std::size_t>(i)] = cell_key(ix, iy, iz);
            m_bucket[static_cast<std::size_t>(i)] =
                static_cast<std::uint32_t>(hash == HashFunction::column ? mod.column_bucket(column_mix(ix, iy), iz)
                                                                        : mod.reduce(teschner_hash(ix, iy, iz)));
        }
        return bad;
    };
    auto put = [&](std::int64_t i, std::size_t k) {
        const Index v = ids ? ids[i] : static_cast<Index>(i);
        const double* p = positions + 3 * static_cast<std::size_t>(v);
        x[k] = static_cast<float>(p[0] - ox);
        y[k] = static_cast<float>(p[1] - oy);
        z[k] = static_cast<float>(p[2] - oz);
        id[k] = v;
        key[k] = m_key[static_cast<std::size_t>(i)];
    };
    // m_bad (reset by reserve()): set before a barrier, read after it; every thread returns the same.
    auto bad_after_barrier = [&](bool bad) {
        if (bad) {
#pragma omp atomic write
            m_bad = 1;
        }
        detail::team_barrier();
        int seen;
#pragma omp atomic read
        seen = m_bad;
        return seen != 0;
    };
    const std::uint32_t* bucket = m_bucket.data();
    std::int32_t* s = start.data();

    if (parts == 1) {
        // Thread 0 builds the table (a stable counting sort); the others wait at the one barrier.
        bool bad = false;
        if (rank == 0) {
            bad = cells(0, count);
            if (!bad) {
                // Counts, inclusive prefix sums (start[b] = the end of bucket b), then the vertices scattered from
                // the last down, each to one before its bucket's current end: stable, and start[b] ends as the
                // bucket's beginning, with no shift of the offsets afterwards.
                std::memset(s, 0, static_cast<std::size_t>(table_size) * sizeof(std::int32_t));
                for (Index i = 0; i < count; ++i)
                    ++s[bucket[i]];
                for (std::int64_t b = 1; b < table_size; ++b)
                    s[b] += s[b - 1];
                s[table_size] = count;
                for (Index i = count - 1; i >= 0; --i)
                    put(i, static_cast<std::size_t>(--s[bucket[i]]));
            }
        }
        return !bad_after_barrier(bad);
    }

    // Several parts: cells split by vertex, then the counting sort split by bucket.
    bool bad = false;
    if (rank < parts) {
        std::int64_t i0, i1;
        detail::team_split(count, rank, parts, i0, i1);
        bad = cells(i0, i1);
    }
    if (bad_after_barrier(bad)) return false;
    if (rank < parts) {
        // This thread's block of buckets [b0, b1): every vertex is looked at, those of the block counted and
        // scattered (in input order: stable); the others go to this thread's spare cursor and spare entry,
        // branch-free. The block's first index is the number of vertices in lower buckets.
        std::int64_t b0, b1;
        detail::team_split(table_size, rank, parts, b0, b1);
        const auto lo = static_cast<std::uint32_t>(b0), width = static_cast<std::uint32_t>(b1 - b0);
        std::int32_t* cur = m_cursor.data();
        const std::uint32_t spare_cursor =
            static_cast<std::uint32_t>(table_size) + 16 * static_cast<std::uint32_t>(rank);
        const std::size_t spare_entry = static_cast<std::size_t>(count) + padding + static_cast<std::size_t>(rank);
        std::memset(cur + b0, 0, static_cast<std::size_t>(b1 - b0) * sizeof(std::int32_t));
        std::int32_t below = 0;
        for (Index i = 0; i < count; ++i) {
            const std::uint32_t b = bucket[i];
            below += b < lo;
            ++cur[b - lo < width ? b : spare_cursor];
        }
        std::int32_t run = below;
        for (std::int64_t b = b0; b < b1; ++b) {
            const std::int32_t c = cur[b];
            s[b] = cur[b] = run;
            run += c;
        }
        if (rank == parts - 1) s[table_size] = run;
        for (Index i = 0; i < count; ++i) {
            const std::uint32_t b = bucket[i];
            const bool mine = b - lo < width;
            const std::int32_t k = cur[mine ? b : spare_cursor]++;
            put(i, mine ? static_cast<std::size_t>(k) : spare_entry);
        }
    }
    detail::team_barrier();
    return true;
}

} // namespace tethash
