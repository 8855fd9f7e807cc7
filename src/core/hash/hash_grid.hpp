#pragma once
/// \file hash_grid.hpp (private to the core)
/// The infinite uniform grid and the hash table of vertices used by the Detector (stage 1).
///
/// A point p lies in cell floor(p · (1/l)) per axis (negative coordinates included); cell coordinates
/// are guarded to |c| < 2^30 (an Error otherwise, never wrap-around). A cell (x, y, z) goes to bucket
/// H(x, y, z) mod n. The table is rebuilt each step as a counting sort of the vertices by bucket into
/// one contiguous array (structure of arrays: float x, y, z relative to an origin, vertex id and the
/// integer cell), so that a bucket is a contiguous index range [start[b], start[b+1]).
///
/// Two hash functions:
/// - teschner: (x·73856093 xor y·19349663 xor z·83492791) mod n on 32-bit wrapping integers (the 2003 paper);
/// - column: (mix(x, y) + z) mod n: the cells of one (x, y) column land in consecutive buckets, so a
///   tet looks up a whole z-run of cells as one (or, wrapping around, two) contiguous bucket ranges.

#include "table_size.hpp"
#include "tethash/detect.hpp"

#include <cstdint>
#include <vector>

namespace tethash {

/// Largest allowed |cell coordinate| (exclusive).
inline constexpr double max_cell_coordinate = 1073741824.0; // 2^30
/// Largest allowed table size.
inline constexpr std::int64_t max_table_size = std::int64_t{1} << 27;

/// floor(x) as an integer for |x| < 2^31 (the caller guards the range): the same value as std::floor, without
/// the library call that a build without SSE4.1 makes for it (measured: 8 % of all instructions of a detection).
inline std::int32_t floor_to_int(double x)
{
    const auto i = static_cast<std::int32_t>(x); // truncation toward zero, exact in range
    return i - (x < static_cast<double>(i));
}

inline std::uint64_t teschner_hash(std::int32_t x, std::int32_t y, std::int32_t z)
{
    return static_cast<std::uint32_t>(static_cast<std::uint32_t>(x) * 73856093u ^
                                      static_cast<std::uint32_t>(y) * 19349663u ^
                                      static_cast<std::uint32_t>(z) * 83492791u);
}

/// The 32-bit key stored with every table entry in place of its three cell coordinates:
/// x mod 2^11 | (y mod 2^11) << 11 | (z mod 2^10) << 22. Not injective on the infinite grid, but a scanned entry
/// is also inside the tet's float box, hence within 2^8 cells of the tet's cell box (float rounding of coordinates
/// up to 2^31 cells from the origin); for cell boxes of at most key_exact_xy × key_exact_xy × key_exact_z cells
/// a key match therefore means the very cell. Bigger cell boxes (tiny cells) compare exact cells instead.
inline std::uint32_t column_key(std::int32_t x, std::int32_t y)
{
    return (static_cast<std::uint32_t>(x) & 0x7ffu) | ((static_cast<std::uint32_t>(y) & 0x7ffu) << 11);
}
inline std::uint32_t cell_key(std::int32_t x, std::int32_t y, std::int32_t z)
{
    return column_key(x, y) | ((static_cast<std::uint32_t>(z) & 0x3ffu) << 22);
}
inline constexpr std::uint32_t key_column_mask = 0x3fffffu;
inline constexpr std::int64_t key_exact_xy = 2048 - 2 * 257 - 1; ///< cells per axis in x and y (1533)
inline constexpr std::int64_t key_exact_z = 1024 - 2 * 257 - 1;  ///< cells in z (509)

/// 64-bit mix of a column (x, y).
inline std::uint64_t column_mix(std::int32_t x, std::int32_t y)
{
    std::uint64_t h = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}

/// Reduces hashes modulo the table size n (mask for powers of two).
struct TableModulus {
    std::uint64_t n = 1;
    std::uint64_t mask = 0; ///< n − 1 when n is a power of two, else 0
    bool pow2 = true;
    explicit TableModulus(std::uint64_t size = 1) : n(size), mask(size - 1), pow2((size & (size - 1)) == 0) {}
    std::uint64_t reduce(std::uint64_t h) const { return pow2 ? (h & mask) : (h % n); }
    /// Bucket of cell z of the column with mix value h (column hash).
    std::uint64_t column_bucket(std::uint64_t h, std::int32_t z) const
    {
        if (pow2) return (h + static_cast<std::uint64_t>(static_cast<std::int64_t>(z))) & mask;
        const std::int64_t zn = static_cast<std::int64_t>(z) % static_cast<std::int64_t>(n);
        const std::uint64_t zm = static_cast<std::uint64_t>(zn < 0 ? zn + static_cast<std::int64_t>(n) : zn);
        return (h % n + zm) % n;
    }
};

/// Stage 1: the vertex table. Keeps its buffers across builds.
class VertexTable {
  public:
    /// Rebuilds the table from the vertices `ids` (or all rows of `positions` when `ids` is null, count
    /// = positions.rows()). `origin` is subtracted before the float conversion. Returns false when a
    /// coordinate is non-finite or a cell coordinate is out of range (the caller diagnoses and throws).
    bool build(const double* positions, const Index* ids, Index count, double cell_size, const double origin[3],
               std::int64_t table_size, HashFunction hash, int threads);
    /// The same, called by every thread of the current OpenMP team (inside a parallel region; outside one it runs
    /// on the calling thread alone) after reserve(count, table_size) on one thread: cells and buckets are split over
    /// the team by vertex, the counting sort by bucket (each thread sorts the vertices of its block of buckets, in
    /// input order). Two barriers; the table is the same for any team size. Returns the same value on every thread.
    bool build_team(const double* positions, const Index* ids, Index count, double cell_size, const double origin[3],
                    std::int64_t table_size, HashFunction hash);
    /// Sizes the buffers for build_team (no allocation when the sizes did not change).
    void reserve(Index count, std::int64_t table_size, int threads);
    /// How many threads of a team of `threads` build_team splits `count` vertices over (1: thread 0 builds the
    /// table alone; then build_team is better called before the parallel region, saving the team a barrier).
    static int team_parts(Index count, int threads);

    std::int64_t table_size() const { return static_cast<std::int64_t>(m_mod.n); }
    const TableModulus& modulus() const { return m_mod; }
    Index size() const { return m_count; }
    std::int64_t memory_bytes() const;

    // Structure of arrays in bucket order, padded by 8 entries at the end (padding never matches: NaN
    // coordinates; never read beyond) and then one spare entry per thread of a team build. 20 bytes per entry.
    std::vector<float> x, y, z;      ///< coordinates relative to the origin, rounded to float
    std::vector<std::int32_t> id;    ///< vertex id
    std::vector<std::uint32_t> key;  ///< cell_key() of the entry's cell
    std::vector<std::int32_t> start; ///< n + 1 offsets

  private:
    TableModulus m_mod;
    Index m_count = 0;
    std::vector<std::uint32_t> m_bucket; ///< per input vertex
    std::vector<std::uint32_t> m_key;    ///< per input vertex
    std::vector<std::int32_t> m_cursor;  ///< team build: scatter cursor per bucket, then one spare slot per thread
    int m_bad = 0;
};

} // namespace tethash
