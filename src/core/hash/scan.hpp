#pragma once
// The bucket-range scan of stage 2 (private header): scalar and AVX2 versions, chosen at run time.
#include "hash_grid.hpp"

#include <cstdint>

namespace tethash::detail {

/// What one tet looks for in a bucket range: entries in column/cell (cx, cy, z0..z1), inside the float box
/// (lo, hi, relative to the table origin), and not one of the tet's own vertices. In scan_ranges the column comes
/// from each range and the z-range [z0, z1] from the query (the same for all ranges of one call).
struct ScanQuery {
    float lo[3], hi[3];
    std::int32_t cx = 0, cy = 0, z0 = 0, z1 = 0;
    Index own[4];
};

struct ScanCounters {
    std::int64_t scanned = 0, collisions = 0, box_rejections = 0, own = 0;
};

/// One bucket range to scan, with the column (cx, cy) its entries must have (their z-range: the query's). 16 bytes.
struct ScanRange {
    std::int32_t begin, end, cx, cy;
};

/// Scans every range of `ranges` for the box and own vertices of `q` and cells in the range's column and
/// q.z0..q.z1 (q.cx/cy ignored); appends the ids to `out` (room for the sum of the range lengths plus 8: the AVX2
/// kernel stores 8 ids at a time); returns how many. With `full_counts` every entry is
/// classified for `counters` (cell, box, own); without, a leaner kernel tests the box first and the cell only
/// for box survivors, and leaves `counters` alone. Both append the same ids in the same order.
/// With `exact_positions` (the n × 3 positions the table was built from, and 1 / cell size): cells are recomputed
/// from the double positions instead of the key test, for cell boxes beyond key_exact_xy / key_exact_z.
std::int32_t scan_ranges(const VertexTable& table, const ScanRange* ranges, std::int32_t count, const ScanQuery& q,
                         Index* out, ScanCounters& counters, bool full_counts = true,
                         const double* exact_positions = nullptr, double inv_cell = 0);

/// A scan kernel of the column hash without the dispatch of scan_ranges: no full counts, no exact positions, and
/// (with AVX2) no z test, only the column's: in the buckets of a column's z-run [z0, z1] (one contiguous range or two
/// pieces wrapping around the table, nz = z1 − z0 + 1 < the table size n), an entry of that column has z ≡ z0 .. z1
/// (mod n), so one outside the z-run is at least n − nz + 1 ≥ 1 cells away from it and the float box rejects it (the
/// float rounding of the box can admit a vertex just outside the double box: then one more candidate for the exact
/// stage 3, never a duplicate, since each entry lies in one range of its column). Not for Teschner's hash, whose bucket
/// of one cell holds other cells of the same column that another z-layer's batch scans too.
using ScanKernel = std::int32_t (*)(const VertexTable&, const ScanRange*, std::int32_t, const ScanQuery&, Index*,
                                    ScanCounters&);
ScanKernel column_scan_kernel();

/// Appends to `out` the ids of the entries [begin, end) of `table` that match `q`; returns how many.
/// `out` must have room for end − begin ids.
std::int32_t scan_bucket_range(const VertexTable& table, std::int32_t begin, std::int32_t end, const ScanQuery& q,
                               Index* out, ScanCounters& counters);

/// "avx2" or "scalar": the version scan_bucket_range uses (environment TETHASH_SIMD=scalar forces scalar).
const char* scan_kernel_name();

} // namespace tethash::detail

namespace tethash::detail {

/// The four face planes of a tet, sign-folded so that inside ⇔ every value n_i·(p − r_i) ≥ 0, plus the
/// weights of the orient3d error bound. Lanes = faces.
struct alignas(32) FacePlanes {
    double rx[4], ry[4], rz[4];
    double nx[4], ny[4], nz[4];
    double mx[4], my[4], mz[4];
};

/// Builds the face planes of tet (A, B, C, D) (each point 3 doubles) with the tet's orientation folded in, and
/// returns that orientation's exact sign (0: flat tet, `f` unusable). The sign comes from face 3's plane at D with
/// the same error bound as the candidate filter; `exact` is set when it needed exact arithmetic.
int face_planes(const double* A, const double* B, const double* C, const double* D, FacePlanes& f, bool& exact);

/// Filtered plane tests of `count` candidates (vertex ids `cand`, positions `P` n × 3). The candidates the filter
/// does not find certainly outside are kept, in order: the k-th kept one's index j in kept[k], its four values in
/// val[4k..4k+3] and in code[k] the bit mask of faces whose sign the filter could not decide (0: certainly inside).
/// Returns how many were kept.
std::int32_t filter_candidates(const FacePlanes& f, const double* P, const Index* cand, std::int32_t count, double* val,
                               std::int8_t* code, std::int32_t* kept);

} // namespace tethash::detail
