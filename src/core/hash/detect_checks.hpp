#pragma once
// Input checks shared by the Detector (src/core/hash/detect.cpp) and the oracle (src/oracle): private header
// (defined in detect_checks.cpp; validate_params with the parameter grammar of detect_grammar.hpp in
// detect_params.cpp).
#include "table_size.hpp"
#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"

#include <span>
#include <vector>

namespace tethash::detail {

/// Throws Error naming the first offending tet/vertex: index out of range, object id arrays of the wrong
/// length or negative ids. A vertex repeated within a tet is no error: such a tet has zero volume and is
/// skipped as degenerate, by the detector and the oracle alike.
void check_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                    std::span<const Index> tet_object);
/// Throws Error on a wrong row count or a non-finite coordinate (naming the vertex).
void check_positions(const PositionsRef& positions, Index num_vertices);

/// Throws Error naming the first parameter out of range (cell size, table size, threads, skin, hash).
void validate_params(const DetectParams& params);

/// Per-object flags expanded to the number of objects in use (1 + largest id; ids ≥ objects.size() get defaults).
struct ObjectFlags {
    std::vector<unsigned char> self_collision; ///< per object
    std::vector<unsigned char> is_static;      ///< per object
};
ObjectFlags object_flags(std::span<const Index> vertex_object, std::span<const Index> tet_object,
                         std::span<const ObjectOptions> objects);

} // namespace tethash::detail
