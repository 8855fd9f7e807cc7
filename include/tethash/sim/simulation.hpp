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
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/surface_mesh.hpp"
#include "tethash/penetration.hpp"
#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/step_stats.hpp"

#include <csignal>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace tethash::sim {

/// Thrown by Simulation::step() when the interrupt flag was set during the step; the state is the step's start.
class Interrupted : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// How far a run can be trusted, kept over its steps so far (Simulation::health()). A passive scene (everything
/// tethash simulates: gravity, ground, contacts, pins; no motors) must not gain energy, and a body must keep its
/// volume unless its material lets its own weight squeeze it.
struct RunHealth {
    double energy_start = 0; ///< total energy at the start (kinetic, elastic, gravity, ground, contact)
    /// What the scene has to spend at the start: its internal energy plus every mass falling over the scene's height
    /// (and to the ground); the growth below is measured against it.
    double energy_scale = 0;
    double energy_growth = 0;  ///< the most (E − energy_start) / energy_scale at the end of any step so far
    double energy_end = 0;     ///< total energy after the last step
    double volume_ratio = 1;   ///< the least volume of the dynamic tets over their start volume, over the steps
    double volume_end = 1;     ///< that ratio after the last step
    double weight_strain = 0;  ///< the largest density · g · height / young of an object: what its weight squeezes
    std::int64_t steps = 0;    ///< steps taken
    std::int64_t substeps = 0; ///< substeps taken (refined steps count theirs)
    std::int64_t refined_steps = 0;  ///< steps taken again in more substeps (tets inverted or a blow-up)
    std::int64_t crossing_steps = 0; ///< of those, steps taken again for a vertex that entered a far part unseen
    /// Steps kept with a far pair met unwatched within a substep, the continuous check's retakes at their cap
    /// (StepStats::continuous_unresolved)
    std::int64_t continuous_unresolved_steps = 0;
    std::int64_t unconverged_substeps = 0; ///< substeps whose iterations reached their cap (vbd: max_iterations)
    std::int64_t inverted_end = 0;         ///< dynamic tets inverted after the last step
    std::int64_t tets = 0;                 ///< dynamic tets

    /// Energy growth above which a run is said to create energy (1 % of energy_scale).
    static constexpr double energy_slack = 0.01;
    /// Volume lost (fraction) above which a run is said to lose volume, unless weight_strain says it should.
    static constexpr double volume_slack = 0.05;
    /// One sentence per problem, for the summary and the warnings; empty when the run can be trusted.
    std::vector<std::string> problems() const;
};

class SimulationImpl;

/// Triangles of the scene's static parts (Simulation::static_surface).
struct StaticSurface {
    meshing::SurfaceMesh surface;
    std::vector<Index> triangle_object; ///< one per triangle: an obstacle's object id, or −1 for the ground
};

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
    /// Warnings gathered at construction: "dt above the explicit stability limit" (symplectic_euler), an object
    /// whose size looks like millimetres or a wrong scale (larger than 20 m, smaller than 5 mm), an object that
    /// starts below the ground or with vertices inside another object.
    const std::vector<std::string>& warnings() const;
    /// Each object's size at the start (the longest extent of its bounding box, in scene units: metres), scene
    /// order, objects with collider = "bsp" left out (as object_vertices).
    std::vector<double> object_sizes() const;
    /// What the steps so far say about the run (energy, volume, refined steps, unconverged iterations).
    const RunHealth& health() const;
    /// A flag that, once non-zero, ends the current step early: the step is rolled back to its start and
    /// step() throws Interrupted. For Ctrl-C (a signal handler sets it); nullptr: none.
    void set_interrupt_flag(const volatile std::sig_atomic_t* flag);

    /// What does not move, as triangles for the output: the collider = "bsp" obstacles' surfaces (object id of each
    /// triangle: the obstacle's contact object id, after the tet objects) and, when the scene has a ground, a square
    /// of it (two triangles, object −1) centred under the scene, its side 4 times the scene's box diagonal (at
    /// least 1 m). Empty when the scene has neither.
    StaticSurface static_surface() const;

    /// Point data (velocity, contact flag, penetration depth) and cell data (object) for a frame,
    /// filtered by scene().output.fields.
    io::Fields output_fields() const;

  private:
    std::unique_ptr<SimulationImpl> m_impl;
};

} // namespace tethash::sim
