#pragma once
// The vbd integrator's checks of tet orientation on whole states (private to tethash::sim). After every step, what
// the step left inverted is turned back (positions only, small moves: restore_after_step). With
// Scene::inversion_guard the sweeps also keep a tet that enters them with W = 6V > 0 so (vertex_stencils.hpp); this
// gives them such a start. Slivers (Model::VolumeTerms::sliver) are not guarded in the sweeps, which would hold a
// flat tet's corners to within its height of where they are, and the body with them.

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

    /// After a step: gives the tets `inverted` in x (stride 4; rows of the model's volume terms, as
    /// find_inverted_tets lists them) their orientation back in small moves (at most restore_move_edges × the
    /// object's mean edge each; a long one, in a tangle of big tets, would put elastic energy into the body) that
    /// keep every other tet of the corner, slivers included, off its floor (below).
    void restore_after_step(double* x, const std::vector<std::int32_t>& inverted);
    /// Within a guarded substep (the sweeps keep what it turns back), the tets inverted in x: moves of any length;
    /// slivers, which the sweeps do not guard, are not held either.
    void restore_in_substep(double* x);

    static constexpr int restore_passes = 16;
    static constexpr double restore_move_edges = 0.05;

  private:
    /// One corner of each tet of m_bad still inverted moves along the volume's gradient towards W = guard_fraction ·
    /// W0, the corner with the shortest way first, each move shortened so that the corner's other tets keep half of
    /// what they have above the guard's floor, and to at most `longest_move` × its object's mean edge; passes until
    /// none is inverted (tets share corners).
    void restore_inverted(double* x, double longest_move, bool hold_slivers);
    /// The fraction (0 … 1] of a move d of vertex v that keeps each of its tets with W > 0 (slivers only if
    /// `hold_slivers`) above half of min(W, guard_fraction · W0).
    double corner_move_allowed(const double* x, std::size_t v, const double d[3], bool hold_slivers) const;

    const Model& m_model;
    std::vector<std::int32_t> m_corners; ///< 4 per tet, oriented so that the rest volume is positive
    detail::Incidences m_tets_at;        ///< vertex → its tets
    std::vector<std::int32_t> m_bad;     ///< inverted tets found
    std::vector<char> m_taken;           ///< vertex id → taken back to its start
};

} // namespace tethash::sim
