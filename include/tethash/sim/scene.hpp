#pragma once
/// \file sim/scene.hpp
/// Description of a simulation: objects, materials, environment, integrator, detector and output.
/// Filled from a TOML scene file (load_scene / parse_scene; format in docs/simulator.md) or in code.
/// Units: SI-like (length m, mass kg, time s) but nothing depends on the choice.

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/sim/model.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace tethash::sim {

enum class Integrator {
    symplectic_euler, ///< v += h M⁻¹ f(x, v); x += h v. Explicit: stable only below ~2/ω_max. Reference.
    implicit_euler,   ///< backward Euler linearised once per step (Baraff & Witkin 1998), sparse solve. Reference.
    vbd,              ///< default: Vertex Block Descent (Chen et al. 2024), per-vertex Newton steps in colour order.
};
/// "1/240", "0.004", "4e-3": seconds, the grammar of the scene's `dt` and the command line's `--dt`; false when the
/// text is not a number or a fraction of two numbers (the sign and range are the caller's to check).
bool parse_seconds(const std::string& text, double& out);
/// "vbd" (alias "block_descent"), "symplectic_euler" (alias "symplectic", "explicit"), "implicit_euler" (alias
/// "implicit"); throws Error naming the value otherwise. The retired "local_global" (Liu et al. 2013) gives an
/// error that names vbd as its replacement.
Integrator parse_integrator(const std::string& name);
const char* to_string(Integrator integrator);

enum class LinearSolver { cg, ldlt };
LinearSolver parse_linear_solver(const std::string& name);
const char* to_string(LinearSolver solver);

/// How a static object collides.
enum class Collider {
    tets, ///< its tets (a surface file is tetrahedralized on load), hashed with the deformable objects
    bsp,  ///< a closed surface kept as a polyhedron: exact inside test against its BSP tree (bsp.hpp), depth and
          ///< direction from its nearest face
};

/// One object of the scene.
struct ObjectSpec {
    std::string name; ///< for messages; default "object K"
    std::string mesh; ///< tet mesh file, or closed surface file (tetrahedralized on load)
    std::optional<meshing::GenerateParams> generate; ///< built-in shape (used when `mesh` is empty)
    std::optional<TetMesh> data;         ///< in-memory mesh (code only; used when mesh and generate are empty)
    int surface_resolution = 16;         ///< lattice resolution when `mesh` is a surface
    Eigen::Vector3d scale{1, 1, 1};      ///< applied first
    Eigen::Vector3d rotate_deg{0, 0, 0}; ///< then rotations about x, y, z (degrees, in that order)
    Eigen::Vector3d translate{0, 0, 0};  ///< then translation
    Eigen::Vector3d velocity{0, 0, 0};   ///< initial velocity of every vertex
    Material material;
    bool self_collision = true;
    bool is_static = false;             ///< never moves: an obstacle (hashed once by the detector)
    Collider collider = Collider::tets; ///< `collider = "bsp"`: a static closed surface as a BSP tree
};

/// Vertices held fixed: by ids (local to `object`, or global when object < 0) and/or by a box.
struct PinRegion {
    int object = -1;             ///< object index, or -1 for all objects
    std::vector<Index> vertices; ///< vertex ids (local to the object if object ≥ 0)
    bool has_box = false;
    Eigen::Vector3d box_min{0, 0, 0}, box_max{0, 0, 0}; ///< closed box, world coordinates at start
};

/// Contact response: penalty force f = k·d·r − c·(v_rel·r) r on the vertex, minus that with barycentric
/// weights on the four vertices of the penetrated tet.
struct ContactParams {
    double stiffness = 0; ///< force / length; 0 = automatic per contact: 50 × the softer object's ω² (young /
                          ///< (density · mean edge²)) × the contact's effective mass (Simulation::contact_stiffness)
    double damping = 0;   ///< force · s / length; 0 = automatic per contact: sqrt(k · effective mass) (half critical)
    double friction = 0;  ///< Coulomb coefficient (0: off)
    bool in_matrix = true; ///< implicit Euler: contact stiffness in the system matrix
    /// A vertex nearer than margin × its object's mean edge to a far boundary face is pushed before it enters (0:
    /// only vertices inside tets are pushed); never more than the clearance it has had since the start. Penetrated
    /// vertices are pushed with their depth plus the margin, so the force does not jump where a vertex crosses the
    /// surface.
    double margin = 0.25;
    /// Vertices and far boundary faces that may meet within a substep (from their velocities) get a contact that
    /// pushes only if the gap closes within the substep's iterations (vbd; the other integrators push positive
    /// depths only). Off: false.
    bool speculative = true;
    /// A boundary edge through a far boundary face (edge_contacts.hpp, found at the start of each substep; the
    /// crossings no vertex-in-tet contact sees) pushes the edge and each edge of that face which itself passes
    /// through the edge's object towards each other, by the distance between them (docs/simulator.md, Contacts,
    /// step 9). Off: false.
    bool edges = false;
};

struct Output {
    int every = -1; ///< write a frame every N steps (0: never; -1, the default: 60 frames per simulated second)
    std::vector<std::string> fields{"velocity", "contact", "depth", "object"}; ///< of these
};

struct Scene {
    std::vector<ObjectSpec> objects;
    Eigen::Vector3d gravity{0, 0, -9.81};
    Ground ground;
    std::vector<PinRegion> pins;
    double dt = 1e-3; ///< time step (s), split into `substeps`
    int steps = 1000;
    int substeps = 1;
    /// A step that leaves more than 1 % of the tets inverted (and more than it started with), or blows up, is
    /// taken again in twice as many substeps, up to this many; `substeps` or less turns the refinement off.
    /// 0 = automatic: 8 × substeps for vbd, off for the reference integrators (their studies measure them as
    /// they are).
    int max_substeps = 0;
    Integrator integrator = Integrator::vbd;
    LinearSolver solver = LinearSolver::cg;
    /// vbd: sweeps over all vertices per substep; 0 = automatic: until they converge (`convergence`), at least 1, at
    /// most `max_iterations`. A fixed count leaves small or stiff bodies unconverged: the sweeps needed grow with
    /// ω h (ω = c / L̄ the material's frequency at the mean edge), which grows as 1 / size at a fixed mesh
    /// (docs/simulator.md, "Convergence at every size").
    int iterations = 0;
    /// vbd, automatic sweeps: a substep has converged when a sweep's moves (in the local Hessians' norm: the energy
    /// they take out) are below this fraction of the largest sweep's, and below a thousandth of the energy the scene
    /// has to spend (or stalled below it); in [0, 1) (0: the energy test and stalls only). The energy test is what
    /// keeps runs from gaining energy; this one buys accuracy: lower values rest closer to the converged state at
    /// a higher cost per step (figures in docs/simulator.md, "Figures behind the code's constants").
    double convergence = 0.3;
    /// vbd, automatic sweeps: the most a substep may take; a substep that reaches it is counted unconverged
    /// (StepStats::unconverged, the run's summary and warnings).
    int max_iterations = 100;
    /// vbd: between sweeps, the coarse space's correction (a lattice over each object, coarse_space.hpp) carries the
    /// long waves that sweeps carry one ring of vertices at a time; false: sweeps alone (the former method).
    bool coarse_space = true;
    /// vbd, automatic sweeps: a step of one substep that gained energy, taken again with tighter tolerances, continues
    /// its sweeps from where they stopped (the same inertial target, contacts and convergence reference); false: it
    /// starts over from the step's start, repeating the sweeps already done (the former way; docs/simulator.md,
    /// "Where a 15 cm step's extra work goes").
    bool resume_retakes = true;
    /// vbd: Chebyshev acceleration of the sweeps (Wang 2015, as in the VBD paper): the estimated spectral radius
    /// ρ of one sweep, in [0, 1); 0 = off; negative (the default) = automatic: off with the coarse space, 0.9
    /// without (a few accelerated sweeps come closer to the converged answer than more plain ones; docs/simulator.md).
    double acceleration = -1;
    /// vbd: keep tets the right way out. A vertex's step never lowers one of its tets (slivers aside) below a
    /// tenth of its rest volume, the sweeps start from a state that inverts none (corners taken back to the
    /// substep's start), and tets still inverted at the end of each substep are turned back corner by corner.
    /// Without it the tets a step leaves inverted are still turned back after the step, which leaves a few in
    /// tangles of thin parts; with it none but slivers stay inverted. Off by default: it holds squeezed regions
    /// back, so a crumpling body collapses more slowly than the converged step (docs/simulator.md, "Inversion
    /// guard", has the figures).
    bool inversion_guard = false;
    /// A step in which a vertex entered a far part (another object, or a part of its own object beyond the local
    /// reach) within one substep with no contact of the substep's start watching it (no penetration of that object,
    /// no margin or speculative contact with it) is taken again in twice the substeps, up to max_substeps: thin
    /// parts that would cross each other within a substep are met by the contacts of shorter substeps instead
    /// (docs/simulator.md, "Crossings"). The end of each step is detected once more for it.
    bool crossing_check = true;
    /// With it, each substep is also swept: continuous detection of the boundary between the substep's start and
    /// end positions (tethash/continuous.hpp) finds a vertex-face or edge-edge impact between different objects, or
    /// far parts of one, that no contact of the substep's start watched (a vertex passing through a whole thin layer
    /// within the substep, an edge through a face with no vertex inside, which the check of where vertices end
    /// cannot see); the step is then taken again in twice the substeps like a crossing (docs/simulator.md,
    /// "Crossings").
    bool continuous_check = false;
    double sweep_tolerance = 0; ///< vbd: > 0 stops sweeping when no vertex moved more than this × its object's mean
                                ///< edge in a sweep (faster, less accurate: 1e-3 stopped a sliding box after one sweep
                                ///< and overstated its friction by 36 %); 0 = always `iterations` sweeps
    double tolerance = 1e-6;    ///< CG relative residual
    ContactParams contact;
    /// Detector parameters. threads defaults to 1 here (not 0 = all cores): the detection of a simulation step
    /// is short, and on a shared machine the OpenMP workers spinning between steps take the core the integrator
    /// needs; `[detector] threads` or `--threads` choose more.
    /// skin defaults to 0.3 × the cell size: candidates are reused while every vertex moved less than half of
    /// it (exact either way, less detection time per step on moving scenes; figures in docs/simulator.md).
    DetectParams detect = [] {
        DetectParams p;
        p.threads = 1;
        p.skin_mode = DetectParams::SkinMode::factor_of_cell_size;
        p.skin = 0.3;
        return p;
    }();
    /// `[detector] table_size = "xF"`: F × the scene's vertex count (rounded up to a power of two, parse_table_size),
    /// resolved when the simulation is built; empty: detect.table_size as given.
    std::string table_size_of_vertices;
    Output output;
    std::string source = "<code>"; ///< file it was read from (messages)
};

/// Reads a TOML scene file. Relative mesh paths are relative to the scene file's folder.
/// Throws Error "FILE:LINE: key 'K': ..." for unknown keys, wrong types and bad values.
Scene load_scene(const std::string& path);
/// Parses scene text; `source_name` appears in messages, `base_dir` resolves relative mesh paths.
Scene parse_scene(const std::string& text, const std::string& source_name = "<scene>",
                  const std::string& base_dir = ".");
/// TOML of the default scene built into the program (generated shapes only, no files needed).
const std::string& default_scene_text();
Scene default_scene();

} // namespace tethash::sim
