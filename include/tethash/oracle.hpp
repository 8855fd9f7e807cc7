#pragma once
/// \file oracle.hpp
/// Brute-force reference for the detector: every vertex against every tet, with the same closed,
/// exact inside test (predicates.hpp) and the same object rules (self-collision off, static objects).
/// For tests, benchmarks and studies; never the product's answer path. Vertices are pre-sorted by x
/// so that each tet only looks at the vertices within its x-extent (still all pairs that can touch).

#include "tethash/detect.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/error.hpp"

#include <span>
#include <vector>

namespace tethash {

/// What the oracle saw.
struct OracleStats {
    std::int64_t degenerate_tets = 0;   ///< zero-volume tets (exact), skipped
    std::int64_t inside_tests = 0;      ///< exact inside tests made (after the bounding-box test)
    std::int64_t exact_evaluations = 0; ///< orientations that needed exact arithmetic
};

/// All contacts (vertex inside or on a tet it does not belong to), sorted by (vertex, tet), with the
/// same rules as Detector: a tet's own four vertices are never contacts (a coincident vertex with another
/// id is); pairs within an object whose options say self_collision = false are skipped; pairs where both
/// objects are static are skipped; zero-volume tets contain nothing. `vertex_object`/`tet_object` may be
/// empty (all 0); `objects` may be shorter than the number of objects (defaults). Throws Error on bad input
/// (same checks as Detector). Parallel over tets when OpenMP is available.
std::vector<Contact> brute_force_contacts(const PositionsRef& positions, const TetsRef& tets,
                                          std::span<const Index> vertex_object = {},
                                          std::span<const Index> tet_object = {},
                                          std::span<const ObjectOptions> objects = {}, OracleStats* stats = nullptr);

/// All edge-face contacts (edge_contacts.hpp) by a loop over every boundary edge and every boundary triangle, with
/// the same exact test (edge_face_crossing) and rules, the "distant" rule of a self pair checked on the vertices'
/// tets (no tet holds a vertex of each); `candidates` counts the pairs the rules allow. Same inputs and errors as
/// find_edge_face_contacts; serial.
EdgeFaceResult brute_force_edge_face_contacts(const TetsRef& tets, const PositionsRef& positions,
                                              std::span<const Index> vertex_object = {},
                                              std::span<const Index> tet_object = {},
                                              std::span<const ObjectOptions> objects = {});

} // namespace tethash
