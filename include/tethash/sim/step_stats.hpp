#pragma once
/// \file sim/step_stats.hpp
/// What one simulation step cost and met (Simulation::last_stats()): its stages' times and its contacts. Apart from
/// simulation.hpp so that the stages that fill it (the contact response) need nothing else of the simulation.

#include <cstdint>

namespace tethash::sim {

/// Timing and contact figures of one step (all its substeps). Times in milliseconds.
struct StepStats {
    double ms_detect = 0;           ///< Detector::detect, the obstacles' and the edge-face contacts (contact.edges)
    double ms_depth = 0;            ///< penetration depth and direction (Penetration::compute)
    double ms_proximity = 0;        ///< margin and speculative contacts (near pairs of far surfaces)
    double ms_response = 0;         ///< contact set-up: filtering, stiffness, damping, per-vertex lists
    double ms_integrate = 0;        ///< forces, matrix assembly, solve, update
    double ms_step = 0;             ///< the whole step (the stages above and ms_checks())
    int threads = 1;                ///< threads the step ran on (threads = 0: chosen step by step)
    std::int64_t contacts = 0;      ///< vertices inside tets at the last substep (contacts())
    std::int64_t near_contacts = 0; ///< margin contacts at the last substep: vertices near a far surface
    std::int64_t edge_contacts = 0; ///< edge contacts at the last substep (contact.edges): edges through far faces
    std::int64_t ignored_local = 0; ///< self-contacts at the last substep left to the elastic terms: the tet lies
                                    ///< within 2 mean edges of the vertex in the rest state (local inversion)
    double max_depth = 0;           ///< largest penetration depth at the last substep (0 without contacts)
    double mean_depth = 0;          ///< mean over contacts at the last substep
    int solver_iterations = 0;      ///< CG iterations (implicit_euler) or sweeps (vbd) summed over substeps
    int substeps = 1;               ///< substeps the step took (scene substeps, or more where it was refined)
    int unconverged = 0;            ///< substeps whose iterations reached their cap unconverged (vbd: max_iterations)
    int crossings = 0; ///< times the step was taken again in more substeps for a vertex that entered a far part unseen
                       ///< (Scene::crossing_check)
    int continuous_crossings = 0; ///< of those, the ones the substep's sweep found (Scene::continuous_check)
    /// 1 when the step kept a far pair that met unwatched within a substep: the continuous check's retakes had
    /// reached their cap (two retakes, or max_substeps), so the step stands as taken
    int continuous_unresolved = 0;
    double ms_continuous = 0; ///< the substeps' sweeps (Scene::continuous_check; part of ms_checks())
    int tightened = 0;        ///< times the step was taken again with tighter tolerances for energy it gained

    /// The step less its stages: its checks (energy, inverted tets, blow-up) and the copies of steps taken again.
    double ms_checks() const
    {
        const double rest = ms_step - ms_detect - ms_depth - ms_proximity - ms_response - ms_integrate;
        return rest > 0 ? rest : 0.0;
    }
};

} // namespace tethash::sim
