#pragma once
/// \file box_grid.hpp (private to the libraries: the core's edge contacts and the simulator's margin contacts;
/// included as "core/hash/box_grid.hpp" from above the core)
/// A uniform grid of boxes hashed into a table, queried by box.
///
/// A box is entered in every cell it meets, cell floor(v · (1/l)) per axis as in the Detector's grid
/// (hash_grid.hpp), each cell in bucket teschner_hash(x, y, z) mod n (n a power of two, chosen by the caller). The
/// entries are counting-sorted by bucket in box order, so the table depends on the input only, and each bucket
/// holds its boxes in a row, in single precision rounded outwards, column by column (lo x, y, z, hi x, y, z): a
/// query tests eight at a time with AVX2 (scalar where the processor lacks it or TETHASH_SIMD=scalar asks so).
/// The float test is a filter: it keeps every box whose double box meets the query's, and the caller's own test
/// decides.

#include "../team.hpp"
#include "hash_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace tethash::detail {

/// A box filter: the entries [begin, end) of a bucket (columns lo x, y, z, hi x, y, z, padded by eight entries)
/// whose box meets the query box q (lo x, y, z, hi x, y, z), in order, into `hits`; returns their count. A
/// comparison with NaN meets (the caller's test decides).
using BoxFilter = std::int32_t (*)(const float* const box[6], std::int32_t begin, std::int32_t end, const float q[6],
                                   std::int32_t* hits);
/// Every kernel this machine runs, scalar first (AVX2: eight entries at a time, chosen at run time).
std::vector<std::pair<const char*, BoxFilter>> box_filters();
/// The kernel the grid uses: "avx2" where the processor has it, unless TETHASH_SIMD=scalar.
const char* box_filter_name();
/// That kernel.
extern const BoxFilter chosen_box_filter;

/// Single precision rounded down / up: a filter's box that contains the double one (float's relative rounding
/// error is at most 2⁻²⁴; the margin taken is 4 × that).
inline float round_down(double v)
{
    const float f = static_cast<float>(v);
    return f - (std::abs(f) * 2.4e-7f + 1e-30f);
}
inline float round_up(double v)
{
    const float f = static_cast<float>(v);
    return f + (std::abs(f) * 2.4e-7f + 1e-30f);
}

class BoxGrid {
  public:
    /// The cell of coordinate v, with inv = 1 / cell size.
    /// (floor(v · inv) by truncation and a correction: the same cell, without a call to the library's floor where
    /// the processor's rounding instruction is not assumed.)
    static std::int64_t cell_of(double v, double inv)
    {
        const double p = v * inv;
        const auto i = static_cast<std::int64_t>(p);
        return i - static_cast<std::int64_t>(p < static_cast<double>(i));
    }

    /// Builds the grid of boxes 0, 1, ..., count − 1 (cells of size `cell`, `buckets` buckets, a power of two).
    /// box_of(i, lo, hi) writes box i's corners, once per box. Alone (rank 0 of 1 part) the calling thread builds it
    /// all; split over a team, every thread of an OpenMP region calls it with the same arguments, its `rank` and the
    /// team's size as `parts`, fills the boxes of its contiguous part of [0, count), counts its
    /// entries per bucket, turns the counts into cursors for its share of the buckets and scatters its own entries:
    /// a bucket holds its boxes in box order whatever the split, and the grid is complete for every thread on return.
    /// (The split is the caller's to give, not read from the enclosing team: a caller inside someone else's region
    /// builds its grid alone.)
    template <class BoxOf>
    void build(double cell, std::size_t buckets, std::size_t count, BoxOf&& box_of, int rank = 0, int parts = 1)
    {
        const auto barrier = [parts] {
            if (parts > 1) team_barrier();
        };
        if (rank == 0) {
            m_inv = 1.0 / cell;
            m_mask = static_cast<std::uint32_t>(buckets - 1);
            m_box.resize(count);
            m_part.resize(static_cast<std::size_t>(parts));
            m_start.resize(buckets + 1);
        }
        barrier();
        Part& mine = m_part[static_cast<std::size_t>(rank)];
        mine.entries.clear();
        mine.count.assign(buckets, 0);
        std::int64_t first = 0, last = 0;
        team_split(static_cast<std::int64_t>(count), rank, parts, first, last);
        for (auto i = static_cast<std::int32_t>(first); i < static_cast<std::int32_t>(last); ++i) {
            double lo[3], hi[3];
            box_of(i, lo, hi);
            enter(i, lo, hi, mine.entries);
        }
        for (const auto& e : mine.entries)
            ++mine.count[e.first];
        barrier();
        // This thread's buckets: their sizes summed over the parts; then, from the sums of the buckets before them,
        // where each part's entries of each bucket go.
        std::int64_t b0 = 0, b1 = 0;
        team_split(static_cast<std::int64_t>(buckets), rank, parts, b0, b1);
        std::int32_t sum = 0;
        for (auto b = static_cast<std::size_t>(b0); b < static_cast<std::size_t>(b1); ++b)
            for (const Part& part : m_part)
                sum += part.count[b];
        mine.bucket_sum = sum;
        barrier();
        std::int32_t at = 0;
        for (int r = 0; r < rank; ++r)
            at += m_part[static_cast<std::size_t>(r)].bucket_sum;
        for (auto b = static_cast<std::size_t>(b0); b < static_cast<std::size_t>(b1); ++b) {
            m_start[b] = at;
            for (Part& part : m_part) {
                const std::int32_t n = part.count[b];
                part.count[b] = at;
                at += n;
            }
        }
        if (rank == parts - 1) {
            m_start[buckets] = at;
            lay_out(static_cast<std::size_t>(at));
        }
        barrier();
        for (const auto& [b, i] : mine.entries)
            place(static_cast<std::size_t>(mine.count[b]++), i);
        barrier();
    }

    /// Calls visit(i) once for every box i whose box meets lo..hi (in single precision: a filter), bucket by bucket
    /// over the cells of lo..hi: stamp[i] = tag marks the boxes met (`stamp`: one per box, none equal to `tag` before
    /// the query). `hits`: scratch. With `repeats_harmless`, a query of one cell takes no stamps: a box two of whose
    /// cells share that cell's bucket is then visited twice, which the caller's answer does not notice.
    template <class Visit>
    void query(const double lo[3], const double hi[3], std::int32_t* stamp, std::int32_t tag,
               std::vector<std::int32_t>& hits, bool repeats_harmless, Visit&& visit) const
    {
        query_above(-1, lo, hi, stamp, tag, hits, repeats_harmless, visit);
    }

    /// query() over the boxes i > `above` only: a bucket holds its boxes in increasing order, so its lower ones are
    /// passed over before the box test (a box of the grid that queries it meets each pair once, and never itself).
    template <class Visit>
    void query_above(std::int32_t above, const double lo[3], const double hi[3], std::int32_t* stamp, std::int32_t tag,
                     std::vector<std::int32_t>& hits, bool repeats_harmless, Visit&& visit) const
    {
        if (m_box.empty()) return;
        std::int64_t c0[3], c1[3];
        float q[6]; // lo x, y, z, hi x, y, z, rounded outwards like the boxes
        for (int k = 0; k < 3; ++k) {
            c0[k] = cell_of(lo[k], m_inv);
            c1[k] = cell_of(hi[k], m_inv);
            q[k] = round_down(lo[k]);
            q[3 + k] = round_up(hi[k]);
        }
        const bool stamps = !repeats_harmless || c0[0] != c1[0] || c0[1] != c1[1] || c0[2] != c1[2];
        const float* const columns[6] = {m_column[0].data(), m_column[1].data(), m_column[2].data(),
                                         m_column[3].data(), m_column[4].data(), m_column[5].data()};
        for (std::int64_t cx = c0[0]; cx <= c1[0]; ++cx)
            for (std::int64_t cy = c0[1]; cy <= c1[1]; ++cy)
                for (std::int64_t cz = c0[2]; cz <= c1[2]; ++cz) {
                    const std::uint32_t b = bucket(cx, cy, cz);
                    std::int32_t first = m_start[b];
                    const std::int32_t last = m_start[b + 1];
                    if (above >= 0)
                        first = static_cast<std::int32_t>(
                            std::upper_bound(m_item.begin() + first, m_item.begin() + last, above) - m_item.begin());
                    if (hits.size() < static_cast<std::size_t>(last - first))
                        hits.resize(static_cast<std::size_t>(last - first));
                    const std::int32_t met = chosen_box_filter(columns, first, last, q, hits.data());
                    for (std::int32_t h = 0; h < met; ++h) {
                        const std::int32_t i = m_item[static_cast<std::size_t>(hits[static_cast<std::size_t>(h)])];
                        if (stamps) {
                            if (stamp[i] == tag) continue;
                            stamp[i] = tag;
                        }
                        visit(i);
                    }
                }
    }

  private:
    std::uint32_t bucket(std::int64_t cx, std::int64_t cy, std::int64_t cz) const
    {
        // The hash takes the coordinates' low 32 bits (it wraps around at 2^32 anyway).
        return static_cast<std::uint32_t>(teschner_hash(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy),
                                                        static_cast<std::int32_t>(cz))) &
               m_mask;
    }

    struct Box {
        float lo[3], hi[3];
    };
    using Entries = std::vector<std::pair<std::uint32_t, std::int32_t>>;
    /// Box i (its slot in m_box exists) rounded outwards into m_box, and an entry (bucket, i) per cell it meets.
    void enter(std::int32_t i, const double lo[3], const double hi[3], Entries& entries)
    {
        Box& box = m_box[static_cast<std::size_t>(i)];
        std::int64_t c0[3], c1[3];
        for (int k = 0; k < 3; ++k) {
            box.lo[k] = round_down(lo[k]);
            box.hi[k] = round_up(hi[k]);
            c0[k] = cell_of(lo[k], m_inv);
            c1[k] = cell_of(hi[k], m_inv);
        }
        for (std::int64_t cx = c0[0]; cx <= c1[0]; ++cx)
            for (std::int64_t cy = c0[1]; cy <= c1[1]; ++cy)
                for (std::int64_t cz = c0[2]; cz <= c1[2]; ++cz)
                    entries.emplace_back(bucket(cx, cy, cz), i);
    }
    /// Sizes the columns and items for `entries` entries, the eight padding entries set (meeting no box).
    void lay_out(std::size_t entries);
    /// Entry `at` (in bucket order) is box i.
    void place(std::size_t at, std::int32_t i)
    {
        const Box& box = m_box[static_cast<std::size_t>(i)];
        for (int k = 0; k < 3; ++k) {
            m_column[k][at] = box.lo[k];
            m_column[3 + k][at] = box.hi[k];
        }
        m_item[at] = i;
    }
    /// One thread's part of a split build: its entries, then its count per bucket, then its cursor per bucket.
    struct Part {
        Entries entries;
        std::vector<std::int32_t> count;
        std::int32_t bucket_sum = 0;
    };
    std::vector<Part> m_part;
    double m_inv = 1;
    std::uint32_t m_mask = 0;
    std::vector<Box> m_box;            ///< per box, rounded outwards
    std::vector<std::int32_t> m_start; ///< per bucket + 1: its entries' range
    /// Per entry, in bucket order, column by column (lo x, y, z, hi x, y, z), padded by eight entries that no box
    /// meets.
    std::vector<float> m_column[6];
    std::vector<std::int32_t> m_item; ///< per entry: its box
};

} // namespace tethash::detail
