#pragma once
/// \file edge_contacts.hpp
/// Edge-face contacts at one instant (discrete, at the end of a step): a boundary edge that crosses a boundary
/// triangle of another object, or of a distant part of its own object. These are the crossings vertex-in-tet
/// detection (detect.hpp) cannot see: two thin parts passing through each other edge through face with no vertex
/// inside any tet.
///
/// The crossing is decided exactly (orient3d of predicates.hpp). Edge (p, q) crosses triangle (a, b, c) when
///  - p and q lie strictly on opposite sides of the triangle's plane: orient3d(a, b, c, p) and orient3d(a, b, c, q)
///    are nonzero and of opposite signs, and
///  - the line pq meets the closed triangle: orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a) are
///    not of opposite strict signs (zeros allowed: the line through an edge or a corner of the triangle counts).
/// Degenerate touching is not a crossing: an end of the edge on the triangle's plane (a vertex touching a face is
/// the vertex-in-tet test's, closed), an edge lying in the plane, a zero-area triangle. The line through a shared
/// edge or corner of neighbouring triangles is reported once per triangle.
///
/// Which pairs are tested (the object rules of DetectParams / ObjectOptions):
///  - between objects: every boundary edge against every boundary triangle, unless both objects are static;
///  - within an object (only when its self_collision is on): the pair is **distant**: no vertex of the edge and no
///    vertex of the triangle are the same or share a tet (are joined by a mesh edge). So a triangle and an edge that
///    touch, or that have a vertex each in one tet, never count; a pair is tested when every vertex of the edge is
///    at least two mesh edges from every vertex of the triangle.
/// An edge's object is its first vertex's, a triangle's its first vertex's (objects do not share vertices).

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace tethash {

/// A boundary edge crossing a boundary triangle. Plain data; arrays of it are sorted by (edge, face).
struct EdgeFaceContact {
    Index edge = -1;                    ///< index into EdgeFaceResult::edges
    Index face = -1;                    ///< index into EdgeFaceResult::faces
    Index edge_vertices[2] = {0, 0};    ///< the edge's vertex ids (first < second)
    Index face_vertices[3] = {0, 0, 0}; ///< the triangle's vertex ids, in boundary_faces' (outward) order
    Index edge_object = 0;
    Index face_object = 0;
    /// The crossing point is (1 − t) x[edge_vertices[0]] + t x[edge_vertices[1]], t in (0, 1).
    double edge_t = 0;
    /// The crossing point is Σ face_bary[k] x[face_vertices[k]]: each ≥ 0, sum 1, exact zeros where the line passes
    /// through the triangle's edge (or corner).
    double face_bary[3] = {0, 0, 0};
    /// The end of the edge (0 or 1) on the inner side of the triangle (inside the triangle's object when its tet is
    /// positively oriented): the end that has passed through.
    int inner_end = 0;
    /// Unit normal of the triangle, pointing from its inner to its outer side: the direction that takes the edge's
    /// inner end back out (and the triangle, with the opposite sign, off the edge).
    double normal[3] = {0, 0, 0};
};

struct EdgeFaceResult {
    Triangles faces;                       ///< the boundary faces (boundary_faces(tets), in its order)
    Edges edges;                           ///< the boundary edges: the faces' edges, (i < j), sorted
    std::vector<EdgeFaceContact> contacts; ///< sorted by (edge, face)
    std::int64_t candidates = 0;           ///< (edge, face) pairs whose boxes overlap and that the rules allow
    /// Candidate reuse (EdgeFaceDetector::set_skin): 1 when the find tested the kept candidates instead of hashing.
    int reused = 0;
    std::int64_t kept_candidates = 0; ///< pairs kept for reuse (0 without a skin or while it is paused)
};

/// What the exact crossing test found for one edge (p, q) and one triangle (a, b, c) (3 doubles each).
struct EdgeFaceCrossing {
    bool crosses = false;
    double edge_t = 0;               ///< valid when crosses
    double face_bary[3] = {0, 0, 0}; ///< valid when crosses
    int inner_end = 0;               ///< valid when crosses: 0 when orient3d(a, b, c, p) < 0, else 1
    double normal[3] = {0, 0, 0};    ///< valid when crosses: unit (b − a) × (c − a), towards the outer end
};
/// The exact test of the rule above (no rounding in the decision).
EdgeFaceCrossing edge_face_crossing(const double* p, const double* q, const double* a, const double* b,
                                    const double* c);

/// Finds the edge-face contacts of a fixed topology at positions that change (an FEM code's steps): the boundary,
/// the vertices' neighbours and the object rules are computed once in set_topology; each find() hashes the boundary
/// triangles' boxes at the new positions into a cell grid and visits the cells of every boundary edge's box.
///
/// With a skin s > 0 (set_skin) consecutive finds share their candidates, as the vertex-in-tet Detector's skin does
/// (docs/ccd.md, "Candidate reuse"): a full find hashes the boxes grown by s/2 per side and keeps every (edge, face)
/// pair they give that the rules allow; a later find whose boundary vertices moved, less their common translation,
/// within s/2 per axis of where that full find saw them tests only the kept pairs. The contacts and `candidates`
/// are those of a find without a skin, bit for bit.
class EdgeFaceDetector {
  public:
    /// `tets` m × 4; `vertex_object`, `tet_object` (empty: all 0) and `objects` (missing: defaults) as for
    /// Detector::set_topology. Throws Error on an index or object id out of range.
    void set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object = {},
                      std::span<const Index> tet_object = {}, std::span<const ObjectOptions> objects = {});
    /// The contacts at `positions` (n × 3, n as in set_topology), valid until the next call. `threads`: 0 = every
    /// OpenMP thread, 1 = serial; the result does not depend on it. Throws Error on a wrong row count, a non-finite
    /// coordinate or a thread count out of range.
    const EdgeFaceResult& find(const PositionsRef& positions, int threads = 0);
    /// Candidate reuse between finds: the skin s (a length; 0, the default, turns it off). Throws Error when s is
    /// negative or not finite. When a full find's kept pairs were never reused (parts move more than s/2 between
    /// finds), the finds after it hash without the skin until one moved less than s/4 since the one before.
    void set_skin(double skin);
    double skin() const { return m_skin; }
    /// A stronger self rule (a simulator's locality rule): a pair within one object is also left out when some
    /// vertex of the edge and some vertex of the triangle lie nearer than `reach[object]` to each other in `rest`
    /// (n × 3; the squared distance below reach², as the simulator computes it). Empty `reach` turns it off (the
    /// default). Throws Error on a wrong row count, a non-finite rest position or a reach per object missing or
    /// negative. Call after set_topology (which turns it off).
    void set_local_reach(const PositionsRef& rest, std::span<const double> reach);
    /// Whether boundary edge `edge` (an index into EdgeFaceResult::edges) crosses at `positions` a boundary face of
    /// `object` that only the local reach rule left out of find() (false without that rule, or for another object
    /// than the edge's). The faces within reach of each edge asked about are listed once and kept.
    bool crosses_locally(Index edge, Index object, const PositionsRef& positions);

  private:
    /// Whether every boundary vertex's displacement from m_reference, less the displacements' common translation (the
    /// centre of their span per axis), is certainly below `limit` per axis (a non-finite position: no).
    bool moved_less_than(const PositionsRef& positions, double limit) const;
    void remember(const PositionsRef& positions);
    /// Some vertex of edge e and some of triangle f are the same or are joined by a mesh edge (share a tet): such a
    /// pair is never a self contact.
    bool near_in_mesh(const Index* e, const Index* f) const;
    /// The local reach rule (set_local_reach) for a pair within `object`: some vertex of e and some of f nearer than
    /// its reach at rest.
    bool near_at_rest(const Index* e, const Index* f, Index object) const;
    /// near_at_rest for boundary edge e and face f, their rest spheres tried first.
    bool local_at_rest(Index e, const Index* ev, Index f, const Index* fv, Index object) const;
    /// The kept pairs tested at `positions` into m_result.
    void find_kept(const PositionsRef& positions, int threads);
    /// Hashes the boxes (grown by `grow` per side), tests the pairs; keeps them for reuse when `keep`.
    void find_full(const PositionsRef& positions, int threads, double grow, bool keep);

    Index m_num_vertices = 0;
    EdgeFaceResult m_result;
    std::vector<Index> m_edge_object, m_face_object; ///< per boundary edge / face
    std::vector<unsigned char> m_self, m_static;     ///< per object
    std::vector<Index> m_offsets, m_neighbours;      ///< vertex → neighbours through tet edges (vertex_adjacency)
    std::vector<double> m_rest;  ///< rest positions (3 per vertex) of the local reach rule (empty: off)
    std::vector<double> m_reach; ///< per object
    struct Sphere {
        double c[3], r;
    };
    std::vector<Sphere> m_edge_sphere, m_face_sphere; ///< rest spheres (centroid, farthest vertex)
    /// Per boundary edge asked about by crosses_locally: the faces only the reach rule leaves out.
    std::vector<std::vector<std::int32_t>> m_local_faces;
    std::vector<unsigned char> m_local_listed; ///< per boundary edge: m_local_faces is filled
    // Candidate reuse.
    double m_skin = 0;
    std::vector<Index> m_boundary_vertices;             ///< the boundary's vertices, increasing
    std::vector<double> m_reference;                    ///< their positions at the last full find (3 per vertex)
    std::vector<std::int32_t> m_kept_edge, m_kept_face; ///< the kept pairs, by edge (empty: none kept)
    bool m_kept_valid = false;
    bool m_paused = false;
    int m_reuses = 0; ///< finds that reused the kept pairs since the last full find
};

/// Every edge-face contact of the boundary of `tets` at `positions` (n × 3): EdgeFaceDetector's set_topology and one
/// find(). Throws Error on an index or object id out of range, a wrong row count, a non-finite coordinate or a thread
/// count out of range.
EdgeFaceResult find_edge_face_contacts(const TetsRef& tets, const PositionsRef& positions,
                                       std::span<const Index> vertex_object = {},
                                       std::span<const Index> tet_object = {},
                                       std::span<const ObjectOptions> objects = {}, int threads = 0);

} // namespace tethash
