#pragma once
// Contacts of one step and their penalty response (private to tethash::sim): detection, the local
// self-contacts left to the elastic terms, penetration depth and direction, per-contact stiffness,
// damping and weights, and the forces and matrix terms every integrator uses.

#include "obstacles.hpp"
#include "proximity.hpp"

#include "tethash/detect.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/penetration.hpp"
#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/step_stats.hpp"

#include <Eigen/Sparse>

#include <utility>
#include <vector>

namespace tethash::sim {

/// Automatic contact and ground penalties: k = contact_rate_factor · ω² · m_eff, ω² the softer object's
/// Model::object_frequency_sq and m_eff the contact's effective mass (the vertex's own mass for the ground). A
/// contact then vibrates at √50 ≈ 7 ω whatever its vertices weigh: about as stiff as the former 10 × the
/// stiffest spring on a graded mesh's typical vertex, softer on its light ones.
inline constexpr double contact_rate_factor = 50;

class ContactResponse {
  public:
    /// A self-contact whose tet lies within this many mean edge lengths of the vertex in the rest state is local
    /// inversion (a fold of the vertex's own neighbourhood), left to the elastic and volume terms: pushing the
    /// vertex out through the nearest face of a neighbouring tet inverts the mesh further.
    static constexpr double local_contact_edges = 2.0;

    /// Builds the detector and penetration topology when some pair of objects can collide; the automatic
    /// penalty per object.
    /// `obstacles` (kept, may be null): static BSP obstacles whose contacts join the tet contacts (tet −1).
    void setup(const Scene& scene, const TetMesh& mesh, const Model& model, const std::vector<ObjectOptions>& options,
               const SceneObstacles* obstacles = nullptr);
    bool enabled() const { return m_enabled; }
    /// The detector's thread count from the next update on (0 = every core); the contacts do not depend on it.
    void set_threads(int threads);

    /// Detects at `x`, drops the local self-contacts, fills depth/direction, adds the margin contacts for a
    /// substep h at velocities v (proximity.hpp), and the coefficients. Adds its times
    /// to `stats` (ms_detect, ms_depth, ms_response).
    void update(const Positions& x, const Positions& v, double h, StepStats& stats);

    /// Contact penalty stiffness between a vertex of object a and a tet of object b whose contact has effective
    /// mass m_eff (see simulation.hpp).
    double pair_stiffness(Index a, Index b, double m_eff) const;

    /// The vertices inside tets (sorted by vertex, tet; then the obstacles'), with their penetration depth and
    /// direction.
    const std::vector<Contact>& contacts() const { return m_contacts; }
    /// The contacts the response pushes: those above with their depth plus the margin, then the margin contacts
    /// (depth = margin − distance, negative for a speculative one). The coefficients below and `stencil` are
    /// indexed by these.
    const std::vector<Contact>& active() const { return m_active; }
    /// The margin contacts (proximity.hpp): depth = the vertex's margin − its distance to the face (< 0: speculative).
    const std::vector<Contact>& margin_contacts() const { return m_near; }
    /// Whether active contact q is a margin contact (they follow the penetrating ones; the edge contacts follow
    /// them, and count as margin contacts here: they are pushed while their depth is positive).
    bool is_margin(size_t q) const { return q >= m_contacts.size(); }
    /// The edge contacts (ContactParams::edges) at the last update: how many follow the margin contacts in active().
    size_t edge_contacts() const { return m_edge_pairs.size(); }
    std::int64_t ignored_local() const { return m_ignored_local; }
    /// Per contact: weight (1 / contacts of the vertex with that object), stiffness, damping, effective mass.
    const std::vector<double>& weight() const { return m_weight; }
    const std::vector<double>& stiffness() const { return m_k; }
    const std::vector<double>& damping() const { return m_c; }
    double friction() const { return m_mu; }
    /// The five nodes of contact q (its vertex, then the tet's four) and their coefficients (1, −b0 … −b3):
    /// the gap along the direction changes by −n · Σ coef_a Δx_a. An obstacle contact (tet −1): the vertex, then
    /// the vertex again four times with coefficient 0 (the obstacle does not move). An edge contact: the first
    /// edge's two ends (1 − s, s) and the second's (−(1 − u), −u), then the first end again with coefficient 0.
    void stencil(size_t q, Index node[5], double coef[5]) const;

    /// f += penalty + friction forces at velocities `vel` for a step h (friction capped so that it cannot reverse
    /// a sliding velocity within h). `cap`: stiffness and damping capped at the explicit limit of h.
    void add_forces(const Positions& vel, Positions& f, double h, bool cap) const;
    void add_triplets(double scale_k, double scale_c, std::vector<Eigen::Triplet<double>>& out) const;
    void apply(double scale_k, double scale_c, const Eigen::VectorXd& p, Eigen::VectorXd& out) const;
    void add_diagonal(double scale_k, double scale_c, Eigen::VectorXd& diag) const;
    double energy() const;
    double max_depth() const;

    /// Exact distances of the contacts' vertices to the penetrated boundaries (error studies).
    std::vector<double> exact_depths(const Positions& x) const;

  private:
    /// Calls visit(q, node, coef, normal) for each contact q with depth > 0: its stencil and direction.
    template <class Visit> void for_each_pushing(Visit&& visit) const;
    /// Calls visit(node, coef, normal, s) for each contact with depth > 0: its stencil, direction and weighted
    /// scale_k · k + scale_c · c (the matrix terms of the three functions above).
    template <class Visit> void for_each_term(double scale_k, double scale_c, Visit&& visit) const;

    /// An edge contact (ContactParams::edges): edge a of one object passes through a far boundary face that has
    /// edge b, and b passes through a boundary face of a's object; a is pushed towards b (and b towards a) along the
    /// segment between their closest points a(s), b(u), by its length. Or (`through`) edge a, in no such pair, passes
    /// in and out of a thin part of another surface: a is pushed along itself, the face f it crosses at a(s)
    /// (barycentric `bary`) the other way, until the part is beyond a's nearer end.
    struct EdgePair {
        Index a[2], b[2];
        double s, u;
        bool through = false;
        Index f[3] = {0, 0, 0};
        double bary[3] = {0, 0, 0};
    };
    /// The edge contacts of the edge-face contacts found at x, into m_edge_pairs and (as Contacts, vertex a's
    /// nearer end, tet −1) appended to m_active.
    void add_edge_contacts(const EdgeFaceResult& found, const Positions& x);

    const TetMesh* m_mesh = nullptr;
    const Model* m_model = nullptr;
    Positions m_rest; // rest (start) positions, for telling local self-contacts from folds
    const SceneObstacles* m_obstacles = nullptr;
    bool m_enabled = false;
    ContactParams m_params;
    Detector m_detector;
    Penetration m_penetration;
    Proximity m_proximity;
    EdgeFaceDetector m_edges; ///< ContactParams::edges
    int m_edge_threads = 1;
    std::vector<EdgePair> m_edge_pairs; ///< the edge contacts, the last m_edge_pairs.size() of m_active
    std::vector<std::pair<Index, Index>> m_edge_keys;
    std::vector<std::pair<Index, Index>> m_edge_count; ///< the edges of m_edge_pairs, sorted (their weights)
    std::vector<Index> m_paired;                       ///< the edges of m_edge_keys, sorted
    /// (vertex, object): the end of a `through` edge contact that passes through that object on its way out; its
    /// own contacts with the object are released (weight 0) while it does.
    std::vector<std::pair<Index, Index>> m_released;
    std::vector<Contact> m_contacts, m_near, m_active;
    std::vector<double> m_weight, m_k, m_c, m_mred;
    std::vector<double> m_object_rate; // automatic penalty per unit effective mass per object (0: static)
    double m_mu = 0;
    std::int64_t m_ignored_local = 0;
};

} // namespace tethash::sim
