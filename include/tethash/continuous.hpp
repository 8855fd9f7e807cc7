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
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace tethash::ccd {

struct ContinuousParams {
    CcdParams query; ///< tolerance and cap of each narrow-phase query
    int threads = 1; ///< OpenMP threads (0: all); the result does not depend on it
    /// ContinuousDetector::detect only: stop testing pairs once one has met (a caller that needs to know whether
    /// anything meets). Whether contacts are found still does not depend on the thread count; which ones, and the
    /// candidate counts, do.
    bool first_only = false;
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
    /// ContinuousDetector::detect only (0 elsewhere): the pairs its grid met, those whose boxes passed the grid's
    /// single-precision test, before the exact box test, the shared-vertex and locality rules and the filter; each
    /// pair once. The broad phase's work, for studying it.
    std::int64_t broad_phase_pairs = 0;
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

/// Continuous detection kept between calls on the same tets: the boundary (faces, edges, vertices) is found once
/// by set_topology, the per-call buffers are kept, so a call costs the broad phase and the narrow phase only. The
/// broad phase is the core's grid of boxes (the hash of box_grid.hpp, as the edge-face contacts and the simulator's
/// margin contacts use): the swept boxes of the faces and of the edges hashed into cells of about a boundary edge,
/// each vertex's and edge's swept box queried, the double boxes tested exactly. detect(x0, x1) is detect_continuous
/// on the kept tets: the same contacts, tois and candidate counts, at every thread count.
class ContinuousDetector {
  public:
    ContinuousDetector();
    ~ContinuousDetector();
    ContinuousDetector(ContinuousDetector&&) noexcept;
    ContinuousDetector& operator=(ContinuousDetector&&) noexcept;

    /// Keeps the boundary of `tets` over `num_vertices` vertices. Throws Error when a tet names a vertex outside
    /// [0, num_vertices).
    void set_topology(const TetsRef& tets, Index num_vertices);
    const Triangles& faces() const;
    const Edges& edges() const;

    /// A locality rule that detect() applies in its broad phase, before the exact box test: a pair is local, and
    /// left out, when the first vertices of its two primitives are of one group g and some vertex of one and some
    /// vertex of the other lie nearer than the group's reach in `rest`: (rest.row(u) − rest.row(w)).squaredNorm() <
    /// reach_sq[g]. (A simulator's parts that the elastic terms keep apart: neighbours on the surface, a fold of a
    /// few edges.) `rest`: num_vertices × 3; `vertex_group`: one group per vertex, in [0, reach_sq.size());
    /// `reach_sq`: per group, ≥ 0 (0: no pair of it is local). Replaces the rule set before; set_topology clears it.
    /// Throws Error naming the input and the entry when a size differs, a group is out of range or a reach or a rest
    /// coordinate is not finite (or a reach negative).
    void set_locality(const PositionsRef& rest, std::span<const Index> vertex_group, std::span<const double> reach_sq);

    /// Decides before the narrow phase whether a candidate pair is tested (kind, then a and b as in
    /// ContinuousContact). Called from several threads at once when params.threads > 1.
    using PairFilter = std::function<bool(ContinuousKind, Index, Index)>;

    /// Continuous detection of the step x0 → x1 (num_vertices × 3 each): detect_continuous's result (the faces and
    /// edges those above). `moving` (empty, or one entry per vertex): only pairs with a vertex whose entry is nonzero
    /// are candidates (a caller that knows where nothing moved enough to meet anything); `keep` (may be empty): only
    /// pairs it accepts reach the narrow phase and the candidate counts (pairs the locality rule left out never reach
    /// it). The result stays valid until the next call.
    /// Throws Error as detect_continuous does.
    const ContinuousResult& detect(const PositionsRef& x0, const PositionsRef& x1, const ContinuousParams& params = {},
                                   std::span<const unsigned char> moving = {}, const PairFilter& keep = {});

  private:
    struct State;
    std::unique_ptr<State> m_state;
};

/// The same by brute force over all pairs (no broad phase): the reference of the tests.
ContinuousResult detect_continuous_brute_force(const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1,
                                               const CcdParams& query = {});

} // namespace tethash::ccd
