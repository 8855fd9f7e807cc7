#pragma once
// The continuous crossing check (private to tethash::sim; Scene::continuous_check): boundary vertex-face and
// edge-edge impacts within a substep, from its start positions to its end, between different objects or far parts
// of one, that the contacts of the substep's start did not watch. Continuous detection (tethash/continuous.hpp) kept
// between calls on the scene's tets.

#include "tethash/continuous.hpp"
#include "tethash/mesh.hpp"
#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace tethash::sim {

class SweepCheck {
  public:
    /// The boundary of `mesh` (its object ids, its rest state) and, per object, whether it collides with itself and
    /// is static. `local_edges`: a self pair whose vertices come within this many mean edges of each other in the
    /// rest state is local (the contacts' rule). `margin`: the contacts' margin in mean edges.
    void setup(const TetMesh& mesh, const Model& model, const std::vector<ObjectOptions>& options,
               const std::vector<std::pair<Index, Index>>& object_vertices, double local_edges, double margin);

    /// Whether some pair meets within x0 → x1 that is neither local, nor static against static, nor watched: a vertex
    /// of it watched against the other's object (`watched`: sorted (vertex, object) pairs of the substep's start
    /// contacts). Only pairs with a vertex whose displacement departs from its object's best affine motion by more
    /// than half of (1 − |A|) × the margin (or, near another object, that moved more than half the margin) are
    /// tested: other pairs cannot close a gap of a margin, and a pair nearer than the margin at the start is watched
    /// by its margin contact.
    bool crossed(const Positions& x0, const Positions& x1, const std::vector<std::pair<Index, Index>>& watched,
                 int threads);
    /// The impacts the last call found (unwatched, far; it stops at the first), and the vertices it marked moving.
    std::int64_t impacts() const { return m_impacts; }
    std::int64_t moving() const { return m_moving_count; }

  private:
    ccd::ContinuousDetector m_detector;
    std::vector<Index> m_object;                  ///< per vertex
    std::vector<double> m_local_sq;               ///< per object: (local_edges × mean edge)²
    std::vector<double> m_margin;                 ///< per object: the contacts' margin (length)
    std::vector<char> m_self, m_static;           ///< per object
    std::vector<std::pair<Index, Index>> m_range; ///< per object: (first vertex, count)
    std::vector<unsigned char> m_moving;
    std::int64_t m_impacts = 0, m_moving_count = 0;
};

} // namespace tethash::sim
