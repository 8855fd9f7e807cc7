#pragma once
/// \file continuous.hpp
/// Continuous detection over a step on tet meshes: every boundary vertex against every boundary face and every
/// boundary edge against every boundary edge, moving linearly from positions x0 (t = 0) to x1 (t = 1), through a
/// broad phase of swept boxes (the box of a primitive's corners at both ends; bounding-volume trees) and the
/// narrow phase of ccd.hpp. So nothing that meets within the step is missed (ccd.hpp's guarantee), including
/// edges that cross faces with no vertex inside a tet.
///
/// Pairs that share a vertex (a face's own corner, edges with a common end) are left out; every other pair is
/// tested, within an object and between objects (object rules are the caller's: the vertices' objects are in the
/// mesh). The contacts are sorted and the same for every thread count.

#include "tethash/ccd.hpp"
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace tethash::ccd {

struct ContinuousParams {
    CcdParams query; ///< tolerance and cap of each narrow-phase query
    int threads = 1; ///< OpenMP threads (0: all); the result does not depend on it
};

enum class ContinuousKind : std::uint8_t {
    vertex_face, ///< a boundary vertex meets a boundary face
    edge_edge,   ///< two boundary edges meet
};

struct ContinuousContact {
    ContinuousKind kind = ContinuousKind::vertex_face;
    Index a = 0;    ///< vertex_face: the vertex id; edge_edge: the lower edge index (into `edges`)
    Index b = 0;    ///< vertex_face: the face index (into `faces`); edge_edge: the higher edge index
    double toi = 0; ///< time of impact in [0, 1], no later than the pair's first contact
    CcdOutcome outcome = CcdOutcome::within_tolerance; ///< how the narrow phase decided
};

struct ContinuousResult {
    Triangles faces;                         ///< the boundary faces (boundary_faces(tets), in its order)
    Edges edges;                             ///< the boundary edges: the faces' edges, (i < j), sorted
    std::vector<ContinuousContact> contacts; ///< sorted by kind (vertex-face first), a, b
    /// Pairs whose swept boxes overlap and that share no vertex: those handed to the narrow phase.
    std::int64_t vertex_face_candidates = 0;
    std::int64_t edge_edge_candidates = 0;
};

/// Continuous detection of the step x0 → x1 (n × 3 each, the same n) of the meshes `tets` (vertex ids into both).
/// Throws Error when the sizes differ, a tet names a vertex outside [0, n), or a coordinate is not finite or above
/// 1e50 in magnitude.
ContinuousResult detect_continuous(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                   const ContinuousParams& params = {});

/// The pairs detect_continuous hands the narrow phase for the step x0 → x1: boundary vertex-face and edge-edge pairs
/// whose swept boxes overlap and that share no vertex (as many as its vertex_face_candidates and
/// edge_edge_candidates). For studying and replaying the narrow phase's workload (`tethash simulate --ccd-queries`).
struct ContinuousCandidates {
    Triangles faces;                               ///< the boundary faces (boundary_faces(tets), in its order)
    Edges edges;                                   ///< the boundary edges: the faces' edges, (i < j), sorted
    std::vector<std::array<Index, 2>> vertex_face; ///< (vertex id, face index), sorted
    std::vector<std::array<Index, 2>> edge_edge;   ///< (lower edge index, higher edge index), sorted
};
/// The candidates of the step, the same for every thread count (`threads`: 0 = all). Throws Error as
/// detect_continuous does.
ContinuousCandidates continuous_candidates(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                           int threads = 1);

/// The same by brute force over all pairs (no broad phase): the reference of the tests.
ContinuousResult detect_continuous_brute_force(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                               const CcdParams& query = {});

} // namespace tethash::ccd
