#pragma once
// The hash table's sizes (private to tethash; defined in hash_grid.cpp and detect_params.cpp): used by the
// detector, the grids of the broad phases and the edge contacts, the table-size grammar and the study's table-size
// sweeps (as "core/table_size.hpp").
#include "tethash/detect.hpp"

#include <cstdint>

namespace tethash {

/// The smallest power of two ≥ n (n ≥ 1).
std::int64_t next_power_of_two(std::int64_t n);
/// The default table size for `vertices` hashed vertices: for the column hash the smallest power of two
/// ≥ 2·vertices (so 2V..4V buckets; bucket ranges are masks), for Teschner's hash the smallest prime ≥ 2·vertices
/// (the xor-product hash needs an odd modulus). At least 1.
/// Below 2V the hash collisions scanned cost more than they save in table memory, beyond 4V the bigger offset
/// array no longer stays in cache (docs/detection.md, "Parameters and defaults", has the figures).
std::int64_t auto_table_size(HashFunction hash, std::int64_t vertices);
/// Smallest prime ≥ n (n ≥ 2).
std::int64_t next_prime(std::int64_t n);

} // namespace tethash
