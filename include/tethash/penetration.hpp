#pragma once
/// \file penetration.hpp
/// Consistent penetration depth and direction for the contacts of a Detector (Heidelberger, Teschner,
/// Keiser, Müller, Gross 2004, "Consistent Penetration Depth Estimation for Deformable Collision Response").
///
/// For every penetrated object B and the set C_B of vertices lying inside B (the contacts with tet_object B):
///  1. border: every mesh edge (i, j) with i in C_B and j not in C_B is intersected with B's boundary
///     surface (boundary_faces of B's tets); the intersection point p and the outward face normal n give
///     vertex i the weighted estimates d_i = Σ w (p - x_i)·n / Σ w and r_i = normalize(Σ w n), w = 1/|p - x_i|².
///  2. propagation: vertices of C_B without an estimate take, wave after wave (breadth first over edges),
///     the weighted average of their valued neighbours j: d_i = Σ μ ((x_j - x_i)·r_j + d_j) / Σ μ,
///     r_i = normalize(Σ μ r_j), μ = 1/|x_j - x_i|².
///  3. fallback: a vertex still without a value (an isolated vertex, no border edge reaching B's surface)
///     takes the closest point on B's boundary surface: depth = distance, direction = (closest - x)/distance
///     (or the face normal when the distance is 0).
/// Depth is in length units and ≥ 0; direction is a unit vector pointing out of B (the way to push the vertex).
/// Nothing here is computed unless called: the detector leaves depth NaN.

#include "tethash/detect.hpp"
#include "tethash/error.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace tethash {

struct PenetrationStats {
    std::int64_t pairs = 0;          ///< distinct (vertex, penetrated object) pairs
    std::int64_t border = 0;         ///< pairs valued from intersected edges (step 1)
    std::int64_t propagated = 0;     ///< pairs valued by propagation (step 2)
    std::int64_t fallback = 0;       ///< pairs valued by the closest-point fallback (step 3)
    std::int64_t intersections = 0;  ///< edge/boundary intersections found
    double ms = 0;                   ///< wall time of compute()
    std::int64_t trees_built = 0;    ///< boundary trees of penetrated objects built (first use, or grown loose)
    std::int64_t trees_refitted = 0; ///< boundary trees kept from an earlier call, refitted to the positions
};

class PenetrationImpl;

/// Keeps the per-object boundary surfaces and the vertex adjacency of a topology between calls, and the
/// boundary trees of the objects penetrated so far: later calls refit them to the new positions (rebuilding
/// one whose boxes have grown loose) and reuse their scratch, so a warmed-up compute() with no more contacts
/// than before allocates nothing. The results do not depend on this history: every call gives bit for bit
/// what a fresh Penetration gives. Not safe for concurrent calls on one object (exact_depths included).
class Penetration {
  public:
    Penetration();
    ~Penetration();
    Penetration(Penetration&&) noexcept;
    Penetration& operator=(Penetration&&) noexcept;
    Penetration(const Penetration&) = delete;
    Penetration& operator=(const Penetration&) = delete;

    /// Same arguments as Detector::set_topology (tets m × 4; object ids per vertex and per tet, empty: all 0).
    void set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object = {},
                      std::span<const Index> tet_object = {});
    void set_topology(const TetMesh& mesh);

    /// Fills depth and direction of every contact in `contacts` (as returned by Detector::detect on
    /// `positions`). Contacts of one vertex with one object get the same values.
    void compute(const PositionsRef& positions, std::span<Contact> contacts, PenetrationStats* stats = nullptr);

    /// Reference for error reporting: for each contact, the exact distance from its vertex to the boundary
    /// surface of the penetrated object (closest point over all its boundary triangles). Size = contacts.size().
    /// Uses (and refits) the kept trees, hence not safe concurrently with another call on this object.
    std::vector<double> exact_depths(const PositionsRef& positions, std::span<const Contact> contacts) const;

  private:
    std::unique_ptr<PenetrationImpl> m_impl;
};

/// One-shot convenience: builds a Penetration for `mesh` and fills `contacts` at mesh.positions.
void compute_penetration(const TetMesh& mesh, std::span<Contact> contacts, PenetrationStats* stats = nullptr);

} // namespace tethash
