#pragma once
// Contact before penetration (private to tethash::sim). The detector reports a vertex once it is inside a tet;
// on thin parts (a strut, a finger, a one-layer sheet) a vertex can cross a whole layer within one substep, and
// then it is inside nothing, or deep inside with a direction that points the wrong way. Margin contacts meet it
// before: a boundary vertex near a far boundary face (of another object, or of its own object but farther than
// the local reach in the rest state) gets a contact with that face, "depth" δ − distance, pushing it out along the
// face's outer side. Pairs are watched out to δ plus how far the two ends may close on each other in the substep
// (1.5 × their travel relative to their objects' mean motion, plus the objects' relative travel): such a contact
// starts with a negative depth and pushes only if the gap closes below δ within the substep (a speculative contact;
// vbd sees it close in its iterations, the other integrators push positive depths only).
// Faces are hashed into the core's grid of boxes (core/hash/box_grid.hpp), cells of two mean edges; each vertex looks
// at the cells its reach covers (one cell when nothing moves relative to its object). Deterministic at any thread
// count: the boundary vertices split into one contiguous range per thread, each with its own scratch, and their
// contacts joined in vertex order.

#include "core/hash/box_grid.hpp"
#include "tethash/detect.hpp"
#include "tethash/sim/model.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <utility>
#include <vector>

namespace tethash::sim {

class Proximity {
  public:
    /// `margin_edges`: δ of each object as a fraction of its mean edge. `reach_edges`: a face of the vertex's own
    /// object nearer than this many of its mean edges in the rest state is local (folds of its own neighbourhood are
    /// the material's business).
    void setup(const TetMesh& mesh, const Positions& rest, const Model& model,
               const std::vector<ObjectOptions>& options, double margin_edges, bool speculative, double reach_edges);
    bool enabled() const { return !m_faces.empty(); }
    /// Threads of the next updates (≥ 1); the contacts do not depend on it.
    void set_threads(int threads) { m_threads = threads > 1 ? threads : 1; }

    /// At positions x (velocities v, substep h): appends to `out` one margin contact per (vertex, object) with the
    /// nearest far face within watch, depth δ − distance (negative: speculative), unless the vertex is already
    /// inside that object (`inside`: contacts sorted by vertex).
    void update(const Positions& x, const Positions& v, double h, const std::vector<Contact>& inside,
                std::vector<Contact>& out);

    /// The margin δ (length) of vertex p: its object's, or less where it has never been that far from a far face
    /// (see update).
    double margin(Index p) const;

  private:
    struct Face {
        Index v[3];
        Index opp; ///< the fourth vertex of its tet (inside)
        Index tet;
        int slot[3]; ///< the corners' columns in the tet
        Index object;
        Eigen::Vector3d rest_centre; ///< centroid in the rest state
        double rest_radius;          ///< its farthest corner's distance in the rest state
    };
    struct Best {
        Index object, face;
        double dist;
        Eigen::Vector3d q;
    };
    /// One thread's scratch: the grid query's hits and per-face stamps, the nearest face per object of the vertex
    /// being queried, the contacts of its range of vertices.
    struct Scratch {
        std::vector<std::int32_t> hits, stamp;
        std::vector<Best> best;
        std::vector<Contact> out;
    };
    /// Mean velocities per object, each boundary vertex's reach, the object pairs' reach.
    void motion(const Positions& v, double h);
    /// Faces' boxes grown by their reach and the largest margin, into the grid.
    void hash_faces(const Positions& x);
    static double face_reach(const std::vector<double>& reach, const Face& f);
    /// One boundary vertex's query: where it is, what it reaches, what is local to it, its nearest far face so far.
    struct Query {
        Index p = -1, op = -1; ///< the vertex and its object
        Eigen::Vector3d xp, rp;
        double r = 0;                                      ///< its reach in the substep
        double reach2 = 0, local_reach = 0, far_reach = 0; ///< its object's local reach (squared), with slack
        double clearance = 0;                              ///< squared distance to the nearest far face
    };
    /// The faces in the cells of q's box: for each far face within watch on its outer side, the nearest per object
    /// into m_best; q.clearance the nearest far face's squared distance.
    void query_cells(Query& q, Scratch& s, const Positions& x) const;
    void visit_face(Query& q, Scratch& s, std::int32_t f, const Positions& x) const;
    /// The vertex's margin from its clearance, and its margin contacts (one per object of m_best that it is not
    /// inside already) appended to `out`.
    void keep_contacts(const Query& q, Scratch& s, const Positions& x, const std::vector<Contact>& inside,
                       std::vector<Contact>& out);
    /// The queries of boundary vertices [begin, end) of m_vertices, their contacts appended to `out`.
    void query_range(size_t begin, size_t end, Scratch& s, const Positions& x, const std::vector<Contact>& inside,
                     std::vector<Contact>& out);
    Contact margin_contact(const Positions& x, Index p, Index op, Index object, Index face, double dist,
                           const Eigen::Vector3d& q) const;

    const Model* m_model = nullptr;
    Positions m_rest;
    std::vector<Face> m_faces;
    std::vector<Index> m_vertices; ///< boundary vertices that can take part in a pair
    std::vector<double> m_margin;  ///< per object
    std::vector<double> m_reach2;  ///< per object: squared local reach (0: self pairs off)
    std::vector<char> m_static;    ///< per object
    double m_edge = 0;             ///< largest mean edge of the moving objects (the grid's cell)
    double m_margin_max = 0;
    bool m_speculative = true;
    bool m_first = true;                 ///< the next update is the first: it sets the start clearances
    std::vector<double> m_vertex_margin; ///< per vertex: min(object margin, largest clearance so far)
    // Motion of the substep.
    std::vector<double> m_reach;           ///< per vertex: 1.5 × its travel relative to its object, clamped
    std::vector<Eigen::Vector3d> m_mean_v; ///< per object: mass-weighted mean velocity
    std::vector<double> m_object_mass;     ///< per object (scratch of motion)
    std::vector<double> m_pair_now;        ///< objects²: how far two objects may close on each other in h
    std::vector<double> m_object_reach;    ///< per object: its widest m_pair_now, for its vertices' query boxes
    // Scratch kept between calls: the grid of the faces' boxes (detail::BoxGrid), one Scratch per thread.
    tethash::detail::BoxGrid m_grid; ///< faces' boxes grown by their reach and the largest margin
    std::vector<Scratch> m_scratch;
    int m_threads = 1;
};

} // namespace tethash::sim
