#pragma once
/// \file sim/model.hpp
/// The mass-spring model, built once from the rest state: one spring per unique tet edge, one volume term per
/// tet, lumped masses, plus gravity and ground. Positions and velocities are n × 3 row-major (Positions).
/// Forces are accumulated (+=) into n × 3 arrays; energies in force × length.
///
/// Why the constants do not depend on the mesh's slivers (Van Gelder 1998, "Approximate simulation of elastic
/// membranes by triangulated spring meshes"): a spring's stiffness is young × (the volume of the tets around its
/// edge) / (rest length)², so a sliver (small volume) gets a small spring and a big tet a stiff one; under a
/// uniform dilation the springs then store the bulk energy of a linear-elastic solid of Poisson ratio 1/4 on any
/// mesh. Masses are lumped from the same volumes, so the stiffness-to-mass ratio of a vertex is ≈ 12 young /
/// (density · edge²) whatever the tets' shapes; vertices whose lumped mass is tiny against their springs and
/// volume terms (all their tets slivers) get a floor that keeps every vertex's explicit limit at or above
/// material_courant · L̄ / c (c = sqrt(young / density) the wave speed, L̄ the object's mean edge): the explicit
/// limit is the material's, not the worst sliver's (see Model::build).

#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Sparse>

#include <cmath>
#include <cstdint>
#include <vector>

namespace tethash::sim {

/// Elastic material of one object.
struct Material {
    double density = 1000; ///< mass per volume (kg/m³); vertex mass = Σ density · |V_tet| / 4 (floored, see build)
    double stiffness = 0;  ///< > 0: every spring gets this stiffness (force / length), young = stiffness / mean edge
    double young = 1e5;    ///< used when stiffness == 0 (force / area): spring k = young · ΣV_adjacent / L0²
    double damping = 0.01; ///< damping as a time (s): dashpot c = damping · k on springs and volume terms
    double volume_stiffness = 1.0; ///< per-tet volume term ½ (volume_stiffness · young / V̂) (V − V0)²
};

/// Ground: the half space {x : n·x < height} is solid.
struct Ground {
    bool enabled = false;
    Eigen::Vector3d normal{0, 0, 1}; ///< normalised on load
    double height = 0;
    double stiffness = 0;  ///< penalty stiffness per vertex (force / length); 0 = automatic per vertex:
                           ///< contact.stiffness if given, else 50 ω² m (ω² its object's object_frequency_sq)
    double damping = 0;    ///< normal damping (force · s / length); 0 = per vertex sqrt(k · m) (half critical)
    double friction = 0.5; ///< Coulomb coefficient
};

struct Springs {
    Edges edges;              ///< e × 2 vertex ids
    std::vector<double> rest; ///< e rest lengths
    std::vector<double> k;    ///< e stiffnesses (force / length)
    std::vector<double> c;    ///< e dashpot coefficients (force · s / length)
};

struct VolumeTerms {
    Tets tets;                ///< tets of the dynamic objects
    std::vector<double> rest; ///< rest signed volumes (> 0 after orientation)
    std::vector<double> k;    ///< stiffness: energy ½ k V0 ((V − V0)/V0)²
    /// Rest volume below a tenth of the regular tet of its mean edge: the volume term is floored (softer than its
    /// own volume would make it), and the vbd integrator restores such a tet's orientation instead of guarding it.
    std::vector<char> sliver;
};

/// Energy split (force × length). `total()` = kinetic + elastic + volume + gravity + ground + contact.
struct Energy {
    double kinetic = 0, spring = 0, volume = 0, gravity = 0, ground = 0, contact = 0;
    double total() const { return kinetic + spring + volume + gravity + ground + contact; }
    double internal() const { return kinetic + spring + volume + ground + contact; } ///< all ≥ 0
};

/// Mass floor of Model::build: no free vertex's explicit limit (Gershgorin, springs and volume terms) below
/// material_courant / ω of its object. A regular mesh's is ≈ 0.2 / ω (a BCC lattice: 0.196), so only vertices
/// whose tets are much worse than regular are floored.
inline constexpr double material_courant = 0.1;

/// Coulomb friction (on the ground and in contacts) is smoothed below a sliding speed of this many times the object's
/// size per second (the largest side of its rest bounding box; Model::friction_speed), so that a scene moves the same
/// whatever the unit of length: 1 mm/s for a body 5 cm across, as the former absolute 1 mm/s, and 2 cm/s at 1 m.
/// Smaller (1e-3: 50 µm/s at 5 cm) made the friction of small stiff bodies too stiff for the sweeps: their drops
/// gained energy (test StiffSmallBodiesNeitherGainEnergyNorBlowUp; docs/simulator.md, "Figures behind the code's
/// constants").
inline constexpr double friction_smoothing = 0.02;

/// Everything computed once from the rest state.
struct Model {
    Springs springs;
    VolumeTerms volumes;
    std::vector<Index> vertex_object;     ///< n: object of each vertex
    std::vector<double> object_mean_edge; ///< per object: mean rest length of its unique edges (0: static)
    /// Per object: ω² = young / (density · L̄²), the material's frequency squared at its mean edge (1/s²; 0:
    /// static). Mass floors and automatic contact penalties are set from it.
    std::vector<double> object_frequency_sq;
    std::vector<double> mass; ///< n lumped masses (static objects: their own mass, unused)
    std::vector<char> fixed;  ///< n: 1 = pinned or static (never moves)
    /// n: the sliding speed (length / s) below which friction on the vertex is smoothed: friction_smoothing × the
    /// size of its object.
    std::vector<double> friction_speed;
    Eigen::Vector3d gravity{0, 0, 0};
    Ground ground;
    /// Per-vertex ground penalty stiffness and damping (n each); empty: ground.stiffness / ground.damping
    /// for every vertex. Simulation fills them when the scene leaves the ground coefficients automatic.
    std::vector<double> ground_k, ground_c;
    double ground_k_at(Index i) const { return ground_k.empty() ? ground.stiffness : ground_k[static_cast<size_t>(i)]; }
    double ground_c_at(Index i) const { return ground_c.empty() ? ground.damping : ground_c[static_cast<size_t>(i)]; }

    /// Springs, volumes and masses of the dynamic objects of `mesh` (rest state = mesh.rest()),
    /// materials per object. Throws Error on a zero-volume tet or a zero-length edge, naming the element.
    static Model build(const TetMesh& mesh, const std::vector<Material>& materials,
                       const std::vector<char>& object_static);

    /// Which forces add_forces() adds, and how.
    struct ForceOptions {
        enum Part : unsigned { springs = 1, damping = 2, volume = 4, gravity = 8, ground = 16, all = 31 };
        unsigned parts = all;
        double h = 0;            ///< > 0: friction capped so that it cannot reverse a sliding velocity in one step of h
        double volume_scale = 1; ///< multiplies the volume term
        double ground_scale = 1; ///< multiplies the ground stiffness and damping
    };
    /// f += spring, damping, volume, gravity and ground forces at (x, v); fixed vertices included (callers ignore
    /// them).
    void add_forces(const Positions& x, const Positions& v, Positions& f) const { add_forces(x, v, f, ForceOptions{}); }
    void add_forces(const Positions& x, const Positions& v, Positions& f, const ForceOptions& opt) const;
    /// What the energy's pass over the tets finds besides their energy (Model::energy with `tets`): the tets whose
    /// signed volume is ≤ 0, by row, and the sum of the signed volumes (what find_inverted_tets gives, bit for bit).
    struct TetScan {
        std::vector<std::int32_t> inverted;
        double volume = 0;
    };
    /// Energies (contact left 0: see Simulation). Summed in blocks of a fixed size, the blocks split over `threads`
    /// and added in order: the same bits at any thread count. With `tets`, the same pass over the tets also fills
    /// it (a step's checks read both: one pass instead of two).
    Energy energy(const Positions& x, const Positions& v, int threads = 1, TetScan* tets = nullptr) const;
    /// Largest eigenvalue bound of M⁻¹K over springs and volume terms (Gershgorin, rest state): ω_max².
    double omega_max_sq(const Positions& x) const;
    /// Explicit (symplectic Euler) stability limit (s) per vertex from the Gershgorin bounds of ω² and of the
    /// damping rate γ: h < (−γ + sqrt(γ² + 4ω²)) / ω² (= 2/ω without damping); minimum over free vertices.
    /// `extra_k_per_vertex` (n, or empty) adds a stiffness per vertex (contact or ground penalty) and
    /// `extra_c_per_vertex` a damping. +inf when nothing is stiff.
    double explicit_dt_limit(const Positions& x, const std::vector<double>& extra_k_per_vertex,
                             const std::vector<double>& extra_c_per_vertex) const;
    /// Adds the (positive semi-definite) stiffness −∂f/∂x of springs (+ volume Gauss–Newton part) and the
    /// damping −∂f/∂v of the dashpots as triplets on the 3n × 3n matrix: scale_k · K + scale_c · C.
    void add_matrix_triplets(const Positions& x, double scale_k, double scale_c,
                             std::vector<Eigen::Triplet<double>>& out) const;
    /// Matrix-free form of the same matrix: out += (scale_k · K + scale_c · C) p for flat 3n vectors; rows and
    /// columns of fixed vertices are skipped (as in add_matrix_triplets).
    void apply_matrix(const Positions& x, double scale_k, double scale_c, const Eigen::VectorXd& p,
                      Eigen::VectorXd& out) const;
    /// diag += the diagonal of scale_k · K + scale_c · C (fixed vertices skipped).
    void add_matrix_diagonal(const Positions& x, double scale_k, double scale_c, Eigen::VectorXd& diag) const;
    Index num_vertices() const { return static_cast<Index>(mass.size()); }

    /// scale_k · K + scale_c · C at fixed positions, with every per-element quantity (spring blocks, volume
    /// gradients, ground coefficients) evaluated once, so that repeated products (CG iterations) cost no
    /// square roots or cross products. Same matrix as apply_matrix / add_matrix_diagonal at those positions.
    /// Products are gathered per vertex over its springs and tets (no write conflicts; serial: an OpenMP region per
    /// CG iteration costs more than the products it shares out; docs/simulator.md has the figure).
    struct Linearised {
        std::vector<Eigen::Matrix3d> spring_block;     ///< per spring
        std::vector<Eigen::Matrix<double, 4, 3>> grad; ///< per volume term: ∇V scaled by sqrt(scale_k k_V / V0)
        std::vector<double> ground;                    ///< per vertex scale_k k_g + scale_c c_g (0: not touching)
        // Vertex adjacency (built on the first update, reused while the model's sizes stay the same).
        std::vector<Index> spring_start, spring_other, spring_id; ///< CSR: vertex → (other end, spring)
        std::vector<Index> tet_start, tet_slot;                   ///< CSR: vertex → 4 · volume term + corner
        mutable std::vector<double> tet_dot;                      ///< scratch: ∇V · p per volume term
        const Model* model = nullptr;
        /// Re-evaluates the blocks at x (the adjacency is kept).
        void update(const Model& m, const Positions& x, double scale_k, double scale_c);
        /// out += matrix · p (flat 3n vectors; rows and columns of fixed vertices skipped).
        void apply(const Eigen::VectorXd& p, Eigen::VectorXd& out) const;
        /// diag += the diagonal of the matrix (fixed vertices skipped).
        void add_diagonal(Eigen::VectorXd& diag) const;
    };
    Linearised linearise(const Positions& x, double scale_k, double scale_c) const;
};

} // namespace tethash::sim
