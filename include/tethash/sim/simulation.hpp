#pragma once
/// \file sim/simulation.hpp
/// A running simulation of a Scene: detection → penetration depth → contact response → integration.
///
/// \code
///   tethash::sim::Simulation sim(tethash::sim::load_scene("meshes/scenes/default.toml"));
///   for (int s = 0; s < sim.scene().steps; ++s) {
///       sim.step();                                   // throws RunFailure on blow-up (state unchanged)
///       use(sim.positions(), sim.energy().total(), sim.max_penetration());
///   }
/// \endcode

#include "tethash/detect.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/penetration.hpp"
#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tethash::sim {

/// Timing and contact figures of one step (all its substeps). Times in milliseconds.
struct StepStats {
    double ms_detect = 0;           ///< Detector::detect
    double ms_depth = 0;            ///< penetration depth and direction (Penetration::compute)
    double ms_proximity = 0;        ///< margin and speculative contacts (near pairs of far surfaces)
    double ms_response = 0;         ///< contact set-up: filtering, stiffness, damping, per-vertex lists
    double ms_integrate = 0;        ///< forces, matrix assembly, solve, update
    std::int64_t contacts = 0;      ///< vertices inside tets at the last substep (contacts())
    std::int64_t near_contacts = 0; ///< margin contacts at the last substep: vertices near a far surface
    std::int64_t ignored_local = 0; ///< self-contacts at the last substep left to the elastic terms: the tet lies
                                    ///< within 2 mean edges of the vertex in the rest state (local inversion)
    double max_depth = 0;           ///< largest penetration depth at the last substep (0 without contacts)
    double mean_depth = 0;          ///< mean over contacts at the last substep
    int solver_iterations = 0;      ///< CG iterations (implicit_euler) or sweeps (vbd) summed over substeps
    int substeps = 1;               ///< substeps the step took (scene substeps, or more where it was refined)
};

class SimulationImpl;

class Simulation {
  public:
    /// Builds objects (reads files / generates shapes), the model and the detector. Throws Error on bad
    /// input (missing file, zero-volume tet, pinned ids out of range...).
    explicit Simulation(const Scene& scene);
    ~Simulation();
    Simulation(Simulation&&) noexcept;
    Simulation& operator=(Simulation&&) noexcept;

    /// Advances one time step (scene().dt, in scene().substeps substeps). Throws RunFailure naming the step
    /// (and substep) and the likely cause when, after any substep, a vertex is NaN/Inf, farther from the scene
    /// than the energy at start can carry it, or the kinetic energy exploded; when the energy after the step
    /// grew by orders of magnitude; or when collision detection fails on the diverged state. The state then
    /// stays at the last good step.
    void step();

    const Scene& scene() const;
    std::int64_t step_index() const; ///< steps completed
    double time() const;             ///< simulated time (s)

    /// The whole scene as one mesh (objects in order, object ids set), positions = current positions.
    const TetMesh& mesh() const;
    const Positions& positions() const;  ///< n × 3
    const Positions& velocities() const; ///< n × 3
    const Model& model() const;
    /// Vertex range [first, first + count) and tet range of object k in mesh(). Objects with collider = "bsp" are
    /// not in mesh(): k counts the other objects, in scene order (scene() lists them only).
    std::pair<Index, Index> object_vertices(int k) const;
    std::pair<Index, Index> object_tets(int k) const;

    Energy energy() const;            ///< at the current state (contact term from the last contacts)
    Eigen::Vector3d momentum() const; ///< Σ m v over non-fixed vertices

    /// Of the last detection, depth/direction filled. A vertex in a collider = "bsp" obstacle has a contact with
    /// tet −1 and tet_object = (number of tet objects) + (the obstacle's rank among the bsp objects).
    const std::vector<Contact>& contacts() const;
    /// Of the last substep: vertices near a far boundary face, not inside it (scene key contact.margin). The face's
    /// tet and the closest point's barycentric coordinates in it (the fourth 0); depth = the vertex's margin minus
    /// its distance to the face (negative: a speculative contact, pushing only if the gap closes); direction away
    /// from the face.
    const std::vector<Contact>& margin_contacts() const;
    double max_penetration() const; ///< max depth over contacts() (0 if none)
    double mean_penetration() const;
    /// Exact distance of each contact's vertex to the penetrated object's boundary (for error studies).
    std::vector<double> exact_depths() const;
    /// Runs detection + penetration at the current positions (updates contacts()).
    void refresh_contacts();

    /// Contact penalty stiffness (force / length) used between a vertex of object `a` and a tet of object `b`
    /// when the contact's effective mass is `effective_mass` (1 / (1/m_vertex + Σ b_j² / m_j) over the tet's
    /// corners j with barycentric weights b_j): scene().contact.stiffness when set, else 50 × the softer
    /// object's Model::object_frequency_sq × effective_mass (a static object takes its partner's), so that no
    /// contact's stiffness-to-mass ratio depends on the mesh. Damping per contact: sqrt(k · effective mass).
    double contact_stiffness(int a, int b, double effective_mass) const;

    const StepStats& last_stats() const;
    /// Explicit stability limit 2/ω_max of the model (s); a warning is issued when dt/substeps exceeds it
    /// with the symplectic integrator.
    double explicit_dt_limit() const;
    /// Warnings gathered at construction (for example "dt above the explicit stability limit").
    const std::vector<std::string>& warnings() const;

    /// Point data (velocity, contact flag, penetration depth) and cell data (object) for a frame,
    /// filtered by scene().output.fields.
    io::Fields output_fields() const;

  private:
    std::unique_ptr<SimulationImpl> m_impl;
};

} // namespace tethash::sim
