#pragma once
/// \file quality.hpp
/// What a simulated body must not end up with, measured against its start: inverted tets and vertices folded
/// through distant parts of their own body. Used by the tests, the stability sweep of `tethash study` and the
/// simulation benchmark, so that all three count the same thing.
#include "tethash/detect.hpp"
#include "tethash/mesh.hpp"
#include "tethash/sim/model.hpp"

#include <cstdint>

namespace tethash::sim {

/// Tets of `mesh` whose signed volume at `mesh.positions` has the other sign than at `start` (same topology).
std::int64_t count_inverted(const TetMesh& mesh, const PositionsRef& start);

/// Sum of the signed volumes of the model's dynamic tets (each oriented positive at rest) at `x`: what a body
/// keeps of its volume, for the energy and volume checks of a run.
double total_volume(const Model& model, const PositionsRef& x);

/// Distinct vertices lying inside a tet of their own object (exact detector) whose nearest corner of that tet was
/// more than `reach` mean edges away at `start`: a fold through a distant part of the body, not a local overlap.
/// (A Simulation keeps no separate rest state: pass the positions it started from.)
std::int64_t count_far_self_penetrations(const TetMesh& mesh, const PositionsRef& start, double reach = 3.0);

/// The same count for many states of one run (every frame): the detector's topology and the far threshold are
/// set up once, not on every call.
class FarSelfPenetrations {
  public:
    /// `mesh` gives the topology and object ids (kept by copy); `start` the positions the distances are measured in.
    FarSelfPenetrations(const TetMesh& mesh, const PositionsRef& start, double reach = 3.0);
    /// count_far_self_penetrations at `positions` (n × 3, the same vertices as the mesh).
    std::int64_t count(const PositionsRef& positions);

  private:
    Detector m_detector;
    Tets m_tets;
    Positions m_start;
    double m_far = 0;
    std::vector<char> m_counted;
};

/// Distinct vertices lying inside a tet of another object (exact detector, contacts between objects only), for many
/// states of one run (every frame): a body entered by another, which contact should have kept out. Static objects
/// count like the others (a vertex inside an obstacle's tet is inside it).
class InsideOtherObjects {
  public:
    /// `mesh` gives the topology and object ids.
    explicit InsideOtherObjects(const TetMesh& mesh);
    /// The count at `positions` (n × 3, the same vertices as the mesh).
    std::int64_t count(const PositionsRef& positions);

  private:
    Detector m_detector;
    std::vector<char> m_counted;
};

} // namespace tethash::sim
