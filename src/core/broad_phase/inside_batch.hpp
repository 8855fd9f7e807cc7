#pragma once
// The closed inside test of many (vertex, tet) pairs at once (private header): the exact stage the broad phases other
// than the hash share (partition_detect.cpp).
#include "tethash/detect.hpp"

#include <cstdint>

namespace tethash::detail {

/// predicates::inside_tet for every pair j < count (vertex[j] in tet[j]; `P` n × 3 positions, `tets` m × 4): with the
/// AVX2 kernels, four pairs at a time in four lanes, each orient3d evaluated with the operations of
/// predicates::orient3d in its order (so the same values bit for bit); a pair whose tet orientation is decided and one
/// of whose faces is decided opposite to it is outside, and any other pair that one of its five orientation filters
/// cannot decide is handed to predicates::inside_tet itself. Writes inside[j] (1: in the closed tet) and, for pairs
/// inside, bary[4j..4j+3]; returns the exact evaluations made (inside_tet's count pair by pair, fewer with AVX2).
std::int64_t inside_tets(const double* P, const Index* tets, const Index* vertex, const Index* tet, std::int32_t count,
                         std::uint8_t* inside, double* bary);

} // namespace tethash::detail
