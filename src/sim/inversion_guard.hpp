#pragma once
// The vbd integrator's inversion guard on whole states (private to tethash::sim; Scene::inversion_guard). The
// sweeps keep a tet that enters them with W = 6V > 0 so (vertex_stencils.hpp); this gives them such a start and
// turns back what is still inverted at the end. Slivers (Model::VolumeTerms::sliver) are not guarded in the
// sweeps, which would hold a flat tet's corners to within its height of where they are, and the body with them:
// they are only turned back at the end.

#include "incidences.hpp"

#include "tethash/sim/model.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tethash::sim {

class InversionGuard {
  public:
    explicit InversionGuard(const Model& model);

    /// The sweeps' starting point x (stride 4) without inverted tets (slivers aside): the free corners of every tet
    /// x inverts go back to their positions in `start` (n × 3), then those of the tets this inverts, and so on, each
    /// vertex once.
    void start_without_inversions(double* x, const Positions& start);

    /// Gives the tets still inverted in x (stride 4) their orientation back: one corner moves along the volume's
    /// gradient to W = guard_fraction · W0, the corner with the shortest way first, each move shortened so that the
    /// corner's other tets (slivers aside) keep half of what they have above the guard's floor; a few passes,
    /// since such tets share corners.
    void restore_inverted(double* x);

  private:
    /// The fraction (0 … 1] of a move d of vertex v that keeps each of its tets (slivers aside) with W > 0 above
    /// half of min(W, guard_fraction · W0).
    double corner_move_allowed(const double* x, std::size_t v, const double d[3]) const;

    const Model& m_model;
    std::vector<std::int32_t> m_corners; ///< 4 per tet, oriented so that the rest volume is positive
    detail::Incidences m_tets_at;        ///< vertex → its tets
    std::vector<std::int32_t> m_bad;     ///< inverted tets found
    std::vector<char> m_taken;           ///< vertex id → taken back to its start
};

} // namespace tethash::sim
