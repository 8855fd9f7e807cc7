// Stage 1: counting sort of the vertices by bucket into one contiguous structure of arrays.
#include "tethash/hash_grid.hpp"

#include "team.hpp"

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
    while (n < want && n < max_table_size) n <<= 1;
    return n;
}

std::int64_t VertexTable::memory_bytes() const
{
    std::int64_t m = static_cast<std::int64_t>(x.capacity() * 3 * sizeof(float) + id.capacity() * sizeof(std::int32_t) +
                                               key.capacity() * sizeof(std::uint32_t) +
                                               start.capacity() * sizeof(std::int32_t) + m_bucket.capacity() * 4 +
                                               m_key.capacity() * 4);
    for (const auto& h : m_hist) m += static_cast<std::int64_t>(h.capacity() * sizeof(std::int32_t));
    return m;
}

namespace {
/// Fewest vertices per thread for which the team build splits the work (below: one thread builds, the others wait).
constexpr Index team_build_min_per_thread = 2048;
/// Most threads whose histograms the team build keeps (each costs 4 bytes per bucket).
constexpr int team_build_max_parts = 8;
} // namespace

bool VertexTable::build(const double* positions, const Index* ids, Index count, double cell_size,
                        const double origin[3], std::int64_t table_size, HashFunction hash, int threads)
{
    bool ok = true;
    if (threads > 1 && count >= 2 * team_build_min_per_thread) {
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
    const int parts = static_cast<int>(std::clamp<Index>(count / team_build_min_per_thread, 1,
                                                         std::min(size, team_build_max_parts)));
#pragma omp single
    {
        m_mod = TableModulus(static_cast<std::uint64_t>(table_size));
        m_count = count;
        m_parts = parts;
        m_bad = 0;
        const std::size_t padded = static_cast<std::size_t>(count) + 8;
        if (x.size() != padded) {
            for (auto* v : {&x, &y, &z}) v->assign(padded, std::numeric_limits<float>::quiet_NaN());
            id.assign(padded, std::numeric_limits<std::int32_t>::min());
            key.assign(padded, 0);
        }
        m_bucket.resize(static_cast<std::size_t>(count));
        m_key.resize(static_cast<std::size_t>(count));
        if (parts == 1) {
            start.assign(static_cast<std::size_t>(table_size) + 1, 0);
        } else {
            start.resize(static_cast<std::size_t>(table_size) + 1);
            if (m_hist.size() < static_cast<std::size_t>(parts)) m_hist.resize(static_cast<std::size_t>(parts));
            m_hist_ptr.resize(static_cast<std::size_t>(parts));
            for (int p = 0; p < parts; ++p) {
                m_hist[static_cast<std::size_t>(p)].resize(static_cast<std::size_t>(table_size));
                m_hist_ptr[static_cast<std::size_t>(p)] = m_hist[static_cast<std::size_t>(p)].data();
            }
        }
        m_partial.resize(static_cast<std::size_t>(size) + 1);
    } // implicit barrier

    const double inv = 1.0 / cell_size;
    const double ox = origin[0], oy = origin[1], oz = origin[2];
    const TableModulus mod = m_mod;
    // Cells, buckets and this part's histogram (parts == 1: the histogram is start[b + 1]).
    if (rank < parts) {
        std::int64_t i0, i1;
        detail::team_split(count, rank, parts, i0, i1);
        std::int32_t* hist;
        if (parts == 1) {
            hist = start.data() + 1;
        } else {
            hist = m_hist[static_cast<std::size_t>(rank)].data();
            std::memset(hist, 0, static_cast<std::size_t>(table_size) * sizeof(std::int32_t));
        }
        int bad = 0;
        for (std::int64_t i = i0; i < i1; ++i) {
            const Index v = ids ? ids[i] : static_cast<Index>(i);
            const double* p = positions + 3 * static_cast<std::size_t>(v);
            const double sx = p[0] * inv, sy = p[1] * inv, sz = p[2] * inv;
            // NaN fails every comparison: caught here too.
            if (!(std::fabs(sx) < max_cell_coordinate && std::fabs(sy) < max_cell_coordinate &&
                  std::fabs(sz) < max_cell_coordinate)) {
                bad = 1;
                continue;
            }
            const std::int32_t ix = floor_to_int(sx), iy = floor_to_int(sy), iz = floor_to_int(sz);
            const auto b = static_cast<std::uint32_t>(hash == HashFunction::column
                                                          ? mod.column_bucket(column_mix(ix, iy), iz)
                                                          : mod.reduce(teschner_hash(ix, iy, iz)));
            m_key[static_cast<std::size_t>(i)] = cell_key(ix, iy, iz);
            m_bucket[static_cast<std::size_t>(i)] = b;
            ++hist[b];
        }
        if (bad) {
#pragma omp atomic write
            m_bad = 1;
        }
    }
    detail::team_barrier();
    int bad_seen;
#pragma omp atomic read
    bad_seen = m_bad;
    if (bad_seen) return false;

    // Scatter one part in input order through its cursors: stable, the same table for any team size.
    auto scatter = [&](std::int64_t i0, std::int64_t i1, std::int32_t* cursor) {
        for (std::int64_t i = i0; i < i1; ++i) {
            const std::int32_t k = cursor[m_bucket[static_cast<std::size_t>(i)]]++;
            const Index v = ids ? ids[i] : static_cast<Index>(i);
            const double* p = positions + 3 * static_cast<std::size_t>(v);
            x[static_cast<std::size_t>(k)] = static_cast<float>(p[0] - ox);
            y[static_cast<std::size_t>(k)] = static_cast<float>(p[1] - oy);
            z[static_cast<std::size_t>(k)] = static_cast<float>(p[2] - oz);
            id[static_cast<std::size_t>(k)] = v;
            key[static_cast<std::size_t>(k)] = m_key[static_cast<std::size_t>(i)];
        }
    };
    if (parts == 1) {
        if (rank == 0) {
            std::int32_t* s = start.data();
            for (std::int64_t b = 0; b < table_size; ++b) s[b + 1] += s[b];
            scatter(0, count, s);
            // start[b] now holds the end of bucket b: shift right by one.
            std::memmove(s + 1, s, static_cast<std::size_t>(table_size) * sizeof(std::int32_t));
            s[0] = 0;
        }
    } else {
        detail::team_counting_offsets(m_hist_ptr.data(), parts, table_size, start.data(), m_partial.data());
        if (rank < parts) {
            std::int64_t i0, i1;
            detail::team_split(count, rank, parts, i0, i1);
            scatter(i0, i1, m_hist[static_cast<std::size_t>(rank)].data());
        }
    }
    detail::team_barrier();
    return true;
}

} // namespace tethash
