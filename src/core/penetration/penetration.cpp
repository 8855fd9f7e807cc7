#include "tethash/penetration.hpp"

#include "../timing.hpp"
#include "../triangle_bvh.hpp"

#include "tethash/geometry.hpp"

#include "tethash/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace tethash {

namespace {

using Vec3 = Eigen::Vector3d;

struct Face {
    Index v[3]; ///< oriented by the caller at use: normal flipped away from `opp`
    Index opp;  ///< the fourth vertex of the tet the face belongs to (inside)
};

Vec3 pos(const PositionsRef& x, Index i)
{
    return x.row(i).transpose();
}

/// Outward unit normal of a boundary face at the current positions (away from the tet's fourth vertex).
Vec3 outward_normal(const PositionsRef& x, const Face& f)
{
    const Vec3 a = pos(x, f.v[0]);
    Vec3 n = (pos(x, f.v[1]) - a).cross(pos(x, f.v[2]) - a);
    if (n.dot(pos(x, f.opp) - a) > 0) n = -n;
    const double len = n.norm();
    return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

/// Segment p + t (q − p), t ∈ [0, 1], against triangle abc (Möller–Trumbore, both sides). Returns t or −1.
/// A nearly parallel pair (|det| ≤ 1e-14 |e1| |e2| |d|) is no hit; that test (three square roots) is made
/// last, on the few pairs that pass the others (on which a zero det gives NaN or ∞ and fails).
double segment_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c)
{
    const Vec3 d = q - p, e1 = b - a, e2 = c - a;
    const Vec3 s1 = d.cross(e2);
    const double det = e1.dot(s1);
    const double inv = 1.0 / det;
    const Vec3 s = p - a;
    const double u = s.dot(s1) * inv;
    if (!(u >= 0 && u <= 1)) return -1;
    const Vec3 s2 = s.cross(e1);
    const double v = d.dot(s2) * inv;
    if (!(v >= 0 && u + v <= 1)) return -1;
    const double t = e2.dot(s2) * inv;
    if (!(t >= 0 && t <= 1)) return -1;
    const double scale = e1.norm() * e2.norm() * d.norm();
    return std::abs(det) > 1e-14 * scale ? t : -1;
}

/// Exact overlap of two boxes (closed).
bool boxes_meet(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi)
{
    return !((alo[0] > bhi[0]) | (alo[1] > bhi[1]) | (alo[2] > bhi[2]) | (ahi[0] < blo[0]) | (ahi[1] < blo[1]) |
             (ahi[2] < blo[2]));
}

/// The triangle tree over one object's boundary faces, kept between calls: refitted to the new positions
/// (same shape) while its boxes stay tight, rebuilt when they have grown loose. Every query answers what a
/// scan over all faces would, ties broken by face index, so the answers do not depend on the tree's shape.
class Bvh {
  public:
    /// Makes the tree and the face boxes match positions x; counts a build or a refit in `built`/`refitted`.
    void update(const PositionsRef& x, const std::vector<Face>& faces, double rebuild_factor, std::int64_t& built,
                std::int64_t& refitted)
    {
        m_faces = &faces;
        const size_t nf = faces.size();
        m_lo.resize(nf);
        m_hi.resize(nf);
        for (size_t f = 0; f < nf; ++f) {
            const Face& fc = faces[f];
            const Vec3 a = pos(x, fc.v[0]), b = pos(x, fc.v[1]), c = pos(x, fc.v[2]);
            m_lo[f] = a.cwiseMin(b).cwiseMin(c);
            m_hi[f] = a.cwiseMax(b).cwiseMax(c);
        }
        auto corners = [&](Index f, Vec3& a, Vec3& b, Vec3& c) {
            const Face& fc = faces[static_cast<size_t>(f)];
            a = pos(x, fc.v[0]);
            b = pos(x, fc.v[1]);
            c = pos(x, fc.v[2]);
        };
        if (m_built) {
            m_tree.refit(corners);
            if (m_tree.cost() <= rebuild_factor * m_built_cost) {
                ++refitted;
                return;
            }
        }
        m_tree.build(static_cast<Index>(nf), corners, 4);
        m_built_cost = m_tree.cost();
        m_built = true;
        ++built;
    }

    bool empty() const { return m_tree.empty(); }
    const Vec3& face_lo(Index f) const { return m_lo[static_cast<size_t>(f)]; }
    const Vec3& face_hi(Index f) const { return m_hi[static_cast<size_t>(f)]; }

    /// Calls visit(f) for every face whose own box meets the box lo..hi, in no particular order.
    template <class Visit> void faces_in_box(const Vec3& lo, const Vec3& hi, Visit&& visit) const
    {
        m_tree.for_box(lo, hi, [&](Index f) {
            if (boxes_meet(m_lo[static_cast<size_t>(f)], m_hi[static_cast<size_t>(f)], lo, hi)) visit(f);
        });
    }

    /// Closest point over faces accepted by `accept(face)`: returns face id (−1 if none) and fills point, dist²;
    /// the least (distance², face id), whatever the tree's shape (TriangleBvh::closest).
    template <class A>
    Index closest(const PositionsRef& x, const Vec3& p, A&& accept, Vec3& best_point, double& best_d2) const
    {
        return m_tree.closest(
            p,
            [&](Index f, Vec3& q) {
                const Face& fc = (*m_faces)[static_cast<size_t>(f)];
                if (!accept(fc)) return false;
                q = closest_point_on_triangle(p, pos(x, fc.v[0]), pos(x, fc.v[1]), pos(x, fc.v[2]));
                return true;
            },
            best_point, best_d2);
    }

  private:
    const std::vector<Face>* m_faces = nullptr;
    detail::TriangleBvh m_tree;
    std::vector<Vec3> m_lo, m_hi; ///< box of every face at the last update
    double m_built_cost = 0;      ///< the tree's cost() when it was built
    bool m_built = false;
};

/// A (vertex, penetrated object) pair and its estimate.
struct Pair {
    Index vertex = 0, object = 0;
    Index next = -1; ///< the vertex's next pair (another object), -1 at the end
    int state = 0;   ///< 0 none, 1 valued (border), 2 valued (propagated), 3 fallback
    double depth = 0;
    Vec3 dir = Vec3::Zero();
};

/// A tree is rebuilt when refitting has made its cost() this many times the cost it had when built.
constexpr double kRebuildFactor = 1.5;

} // namespace

class PenetrationImpl {
  public:
    Index n = 0;
    Index objects = 0;
    std::vector<Index> vertex_object;
    Adjacency adjacency;
    std::vector<std::vector<Face>> faces; // boundary faces per object
    bool ready = false;

    // Kept between calls (sized by the largest call so far): the trees of the objects penetrated so far,
    // and the scratch of compute().
    std::vector<Bvh> trees;                      // per object
    std::vector<Index> head;                     // per vertex: its first pair, -1 (reset after every call)
    std::vector<Pair> pairs;                     // (vertex, object) pairs in order of first contact
    std::vector<Index> contact_slot;             // per contact: its pair
    std::vector<char> need;                      // per object: penetrated in this call
    std::vector<Index> wave;                     // pairs valued by the current propagation round
    std::vector<std::pair<double, Vec3>> values; // their values
    /// A face near a vertex's border edges, with its box.
    struct Candidate {
        double lo[3], hi[3];
        Index face;
        Index v[3];
    };
    std::vector<Candidate> candidates;
    std::vector<Index> border; // a vertex's border neighbours

    void set(const TetsRef& tets, Index num_vertices, std::span<const Index> vobj, std::span<const Index> tobj);
    /// Brings the trees of the objects flagged in `need` to positions x (refit or build).
    void update_trees(const PositionsRef& x, PenetrationStats& st);
    /// Closest point on object b's boundary to vertex i, ignoring faces touching i or its neighbours.
    bool closest(const PositionsRef& x, const Bvh& tree, Index i, Vec3& point, double& dist) const;
    /// The pair of (v, o), -1 if none.
    Index find(Index v, Index o) const
    {
        for (Index q = head[static_cast<size_t>(v)]; q >= 0; q = pairs[static_cast<size_t>(q)].next)
            if (pairs[static_cast<size_t>(q)].object == o) return q;
        return -1;
    }
    bool near_vertex(const Face& f, Index i) const
    {
        for (Index a : f.v) {
            if (a == i) return true;
            const auto b = adjacency.neighbours.begin() + adjacency.offsets[static_cast<size_t>(i)];
            const auto e = adjacency.neighbours.begin() + adjacency.offsets[static_cast<size_t>(i) + 1];
            if (std::binary_search(b, e, a)) return true;
        }
        return false;
    }
    void border_estimate(const PositionsRef& x, Pair& p, PenetrationStats& st);
};

void PenetrationImpl::set(const TetsRef& tets, Index num_vertices, std::span<const Index> vobj,
                          std::span<const Index> tobj)
{
    const Index m = static_cast<Index>(tets.rows());
    if (num_vertices < 0) throw Error("penetration: negative vertex count");
    if (!vobj.empty() && static_cast<Index>(vobj.size()) != num_vertices)
        throw Error("penetration: vertex_object has " + std::to_string(vobj.size()) + " entries for " +
                    std::to_string(num_vertices) + " vertices");
    if (!tobj.empty() && static_cast<Index>(tobj.size()) != m)
        throw Error("penetration: tet_object has " + std::to_string(tobj.size()) + " entries for " + std::to_string(m) +
                    " tets");
    for (Index t = 0; t < m; ++t)
        for (int k = 0; k < 4; ++k)
            if (tets(t, k) < 0 || tets(t, k) >= num_vertices)
                throw Error("penetration: tet " + std::to_string(t) + " has vertex index " +
                            std::to_string(tets(t, k)) + " out of range [0, " + std::to_string(num_vertices) + ")");
    n = num_vertices;
    vertex_object.assign(vobj.begin(), vobj.end());
    if (vertex_object.empty()) vertex_object.assign(static_cast<size_t>(n), 0);
    objects = 0;
    for (Index o : vertex_object)
        objects = std::max(objects, o + 1);
    for (Index o : tobj)
        objects = std::max(objects, o + 1);
    if (m > 0) objects = std::max<Index>(objects, 1);
    adjacency = vertex_adjacency(tets, n);

    // Boundary faces: faces of exactly one tet, with that tet's fourth vertex for orientation.
    struct Key {
        std::array<Index, 3> s;
        Index tet;
        int face;
    };
    static constexpr int kFace[4][4] = {{1, 2, 3, 0}, {0, 3, 2, 1}, {0, 1, 3, 2}, {0, 2, 1, 3}};
    std::vector<Key> keys;
    keys.reserve(static_cast<size_t>(4 * m));
    for (Index t = 0; t < m; ++t)
        for (int f = 0; f < 4; ++f) {
            std::array<Index, 3> s{tets(t, kFace[f][0]), tets(t, kFace[f][1]), tets(t, kFace[f][2])};
            std::sort(s.begin(), s.end());
            keys.push_back({s, t, f});
        }
    std::sort(keys.begin(), keys.end(),
              [](const Key& a, const Key& b) { return a.s < b.s || (a.s == b.s && a.tet < b.tet); });
    faces.assign(static_cast<size_t>(objects), {});
    for (size_t a = 0; a < keys.size();) {
        size_t b = a + 1;
        while (b < keys.size() && keys[b].s == keys[a].s)
            ++b;
        if (b - a == 1) {
            const Key& k = keys[a];
            Face fc;
            for (int j = 0; j < 3; ++j)
                fc.v[j] = tets(k.tet, kFace[k.face][j]);
            fc.opp = tets(k.tet, kFace[k.face][3]);
            const Index o = tobj.empty() ? 0 : tobj[static_cast<size_t>(k.tet)];
            faces[static_cast<size_t>(o)].push_back(fc);
        }
        a = b;
    }
    trees.assign(static_cast<size_t>(objects), Bvh{});
    head.assign(static_cast<size_t>(n), -1);
    pairs.clear();
    // The per-vertex scratch at its largest, so that no later call has to grow it.
    size_t most_faces = 0, most_neighbours = 0;
    for (const auto& f : faces)
        most_faces = std::max(most_faces, f.size());
    for (Index v = 0; v < n; ++v)
        most_neighbours = std::max(most_neighbours, static_cast<size_t>(adjacency.offsets[static_cast<size_t>(v) + 1] -
                                                                        adjacency.offsets[static_cast<size_t>(v)]));
    candidates.reserve(most_faces);
    border.reserve(most_neighbours);
    ready = true;
}

void PenetrationImpl::update_trees(const PositionsRef& x, PenetrationStats& st)
{
    for (Index o = 0; o < objects; ++o)
        if (need[static_cast<size_t>(o)])
            trees[static_cast<size_t>(o)].update(x, faces[static_cast<size_t>(o)], kRebuildFactor, st.trees_built,
                                                 st.trees_refitted);
}

void PenetrationImpl::border_estimate(const PositionsRef& x, Pair& p, PenetrationStats& st)
{
    const Vec3 xi = pos(x, p.vertex);
    const auto& fs = faces[static_cast<size_t>(p.object)];
    const Bvh& tree = trees[static_cast<size_t>(p.object)];
    // One tree query for the box around all of the vertex's border edges, then every edge against the faces
    // found whose box meets the edge's.
    border.clear();
    Vec3 lo = xi, hi = xi;
    for (Index a = adjacency.offsets[static_cast<size_t>(p.vertex)];
         a < adjacency.offsets[static_cast<size_t>(p.vertex) + 1]; ++a) {
        const Index j = adjacency.neighbours[static_cast<size_t>(a)];
        if (find(j, p.object) >= 0) continue;
        border.push_back(j);
        const Vec3 xj = pos(x, j);
        lo = lo.cwiseMin(xj);
        hi = hi.cwiseMax(xj);
    }
    if (border.empty()) return;
    // Faces through the vertex itself never count; the others are copied with their boxes, side by side.
    candidates.clear();
    tree.faces_in_box(lo, hi, [&](Index f) {
        const Face& fc = fs[static_cast<size_t>(f)];
        if (fc.v[0] == p.vertex || fc.v[1] == p.vertex || fc.v[2] == p.vertex) return;
        Candidate c;
        for (int k = 0; k < 3; ++k) {
            c.lo[k] = tree.face_lo(f)[k];
            c.hi[k] = tree.face_hi(f)[k];
        }
        c.face = f;
        for (int k = 0; k < 3; ++k)
            c.v[k] = fc.v[k];
        candidates.push_back(c);
    });
    if (candidates.empty()) return;
    double wsum = 0, dsum = 0;
    Vec3 nsum = Vec3::Zero();
    for (const Index j : border) {
        const Vec3 xj = pos(x, j);
        const Vec3 slo = xi.cwiseMin(xj), shi = xi.cwiseMax(xj);
        double best_t = 2;
        Index best_f = -1;
        for (const Candidate& c : candidates) {
            // Plain comparisons, all evaluated (no early exit): most candidates fail one of them.
            const bool meet = (c.lo[0] <= shi[0]) & (c.hi[0] >= slo[0]) & (c.lo[1] <= shi[1]) & (c.hi[1] >= slo[1]) &
                              (c.lo[2] <= shi[2]) & (c.hi[2] >= slo[2]);
            if (!meet) continue;
            if (c.v[0] == j || c.v[1] == j || c.v[2] == j) continue;
            const Index f = c.face;
            const double t = segment_triangle(xi, xj, pos(x, c.v[0]), pos(x, c.v[1]), pos(x, c.v[2]));
            if (t >= 0 && (t < best_t || (t == best_t && f < best_f))) {
                best_t = t;
                best_f = f;
            }
        }
        if (best_f < 0) continue;
        ++st.intersections;
        const Vec3 hit = xi + best_t * (xj - xi);
        const Vec3 nrm = outward_normal(x, fs[static_cast<size_t>(best_f)]);
        const double dist2 = (hit - xi).squaredNorm();
        const double w = 1.0 / std::max(dist2, 1e-300);
        wsum += w;
        dsum += w * (hit - xi).dot(nrm);
        nsum += w * nrm;
    }
    if (wsum > 0 && nsum.norm() > 0) {
        p.depth = dsum / wsum;
        p.dir = nsum.normalized();
        p.state = 1;
        ++st.border;
    }
}

bool PenetrationImpl::closest(const PositionsRef& x, const Bvh& tree, Index i, Vec3& point, double& dist) const
{
    double d2 = 0;
    const Vec3 p = pos(x, i);
    const Index obj = vertex_object[static_cast<size_t>(i)];
    // Faces of i's own neighbourhood are skipped: for self-collisions they would be at distance ~0.
    const Index best = tree.closest(
        x, p, [&](const Face& f) { return vertex_object[static_cast<size_t>(f.v[0])] != obj || !near_vertex(f, i); },
        point, d2);
    if (best < 0) return false;
    dist = std::sqrt(d2);
    return true;
}

Penetration::Penetration() : m_impl(std::make_unique<PenetrationImpl>()) {}
Penetration::~Penetration() = default;
Penetration::Penetration(Penetration&&) noexcept = default;
Penetration& Penetration::operator=(Penetration&&) noexcept = default;

void Penetration::set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                               std::span<const Index> tet_object)
{
    m_impl->set(tets, num_vertices, vertex_object, tet_object);
}

void Penetration::set_topology(const TetMesh& mesh)
{
    m_impl->set(mesh.tets, mesh.num_vertices(), mesh.vertex_object, mesh.tet_object);
}

void Penetration::compute(const PositionsRef& x, std::span<Contact> contacts, PenetrationStats* stats)
{
    const auto t0 = detail::Clock::now();
    PenetrationImpl& s = *m_impl;
    if (!s.ready) throw Error("penetration: set_topology was not called");
    if (x.rows() != s.n)
        throw Error("penetration: positions have " + std::to_string(x.rows()) + " rows, topology has " +
                    std::to_string(s.n) + " vertices");
    PenetrationStats st;

    // Every contact is checked before the per-vertex table is touched, so a refusal leaves it clean.
    for (size_t c = 0; c < contacts.size(); ++c) {
        const Contact& ct = contacts[c];
        if (ct.vertex < 0 || ct.vertex >= s.n || ct.tet_object < 0 || ct.tet_object >= s.objects)
            throw Error("penetration: contact " + std::to_string(c) + " has vertex " + std::to_string(ct.vertex) +
                        " / tet object " + std::to_string(ct.tet_object) + " out of range");
    }

    // (vertex, penetrated object) pairs, chained per vertex from s.head.
    std::vector<Pair>& pairs = s.pairs;
    pairs.clear();
    // The per-vertex table is left clean however this call ends (an allocation failure included).
    struct ClearHead {
        PenetrationImpl& s;
        ~ClearHead()
        {
            for (const Pair& p : s.pairs)
                s.head[static_cast<size_t>(p.vertex)] = -1;
        }
    } clear_head{s};
    s.contact_slot.resize(contacts.size());
    s.need.assign(static_cast<size_t>(s.objects), 0);
    for (size_t c = 0; c < contacts.size(); ++c) {
        const Contact& ct = contacts[c];
        Index q = s.find(ct.vertex, ct.tet_object);
        if (q < 0) {
            q = static_cast<Index>(pairs.size());
            Pair p;
            p.vertex = ct.vertex;
            p.object = ct.tet_object;
            p.next = s.head[static_cast<size_t>(ct.vertex)];
            pairs.push_back(p);
            s.head[static_cast<size_t>(ct.vertex)] = q;
        }
        s.contact_slot[c] = q;
        s.need[static_cast<size_t>(ct.tet_object)] = 1;
    }
    st.pairs = static_cast<std::int64_t>(pairs.size());
    s.wave.reserve(pairs.size());
    s.values.reserve(pairs.size());
    s.update_trees(x, st);
    auto find = [&](Index v, Index o) { return s.find(v, o); };

    // 1. Border: edges from a colliding vertex to a non-colliding neighbour, intersected with the surface.
    for (Pair& p : pairs)
        s.border_estimate(x, p, st);

    // 2. Propagation inwards, wave by wave: only values from earlier waves are used.
    std::vector<Index>& wave = s.wave;
    auto& values = s.values;
    for (int round = 0;; ++round) {
        wave.clear();
        values.clear();
        for (Index q = 0; q < static_cast<Index>(pairs.size()); ++q) {
            Pair& p = pairs[static_cast<size_t>(q)];
            if (p.state) continue;
            const Vec3 xi = pos(x, p.vertex);
            double msum = 0, dsum = 0;
            Vec3 rsum = Vec3::Zero();
            for (Index a = s.adjacency.offsets[static_cast<size_t>(p.vertex)];
                 a < s.adjacency.offsets[static_cast<size_t>(p.vertex) + 1]; ++a) {
                const Index j = s.adjacency.neighbours[static_cast<size_t>(a)];
                const Index qj = find(j, p.object);
                if (qj < 0) continue;
                const Pair& pj = pairs[static_cast<size_t>(qj)];
                if (!pj.state) continue;
                const Vec3 xj = pos(x, j);
                const double mu = 1.0 / std::max((xj - xi).squaredNorm(), 1e-300);
                msum += mu;
                dsum += mu * ((xj - xi).dot(pj.dir) + pj.depth);
                rsum += mu * pj.dir;
            }
            if (msum > 0 && rsum.norm() > 0) {
                wave.push_back(q);
                values.emplace_back(dsum / msum, rsum.normalized());
            }
        }
        if (wave.empty()) break;
        for (size_t w = 0; w < wave.size(); ++w) {
            Pair& p = pairs[static_cast<size_t>(wave[w])];
            p.depth = values[w].first;
            p.dir = values[w].second;
            p.state = 2;
            ++st.propagated;
        }
    }

    // 3. Fallback: closest point on the penetrated object's boundary.
    for (Pair& p : pairs) {
        if (p.state) continue;
        Vec3 point;
        double dist = 0;
        if (s.closest(x, s.trees[static_cast<size_t>(p.object)], p.vertex, point, dist)) {
            p.depth = dist;
            const Vec3 d = point - pos(x, p.vertex);
            p.dir = dist > 0 ? Vec3(d / dist) : Vec3::UnitZ();
        } else {
            p.depth = 0;
            p.dir = Vec3::UnitZ();
        }
        p.state = 3;
        ++st.fallback;
    }

    for (size_t c = 0; c < contacts.size(); ++c) {
        const Pair& p = pairs[static_cast<size_t>(s.contact_slot[c])];
        contacts[c].depth = std::max(0.0, p.depth);
        for (int k = 0; k < 3; ++k)
            contacts[c].direction[k] = p.dir[k];
    }
    st.ms = detail::ms_since(t0);
    if (stats) *stats = st;
}

std::vector<double> Penetration::exact_depths(const PositionsRef& x, std::span<const Contact> contacts) const
{
    PenetrationImpl& s = *m_impl; // the kept trees are brought to x (see the header)
    if (!s.ready) throw Error("penetration: set_topology was not called");
    if (x.rows() != s.n)
        throw Error("penetration: positions have " + std::to_string(x.rows()) + " rows, topology has " +
                    std::to_string(s.n) + " vertices");
    s.need.assign(static_cast<size_t>(s.objects), 0);
    for (const Contact& c : contacts) {
        if (c.vertex < 0 || c.vertex >= s.n || c.tet_object < 0 || c.tet_object >= s.objects)
            throw Error("penetration: contact with vertex " + std::to_string(c.vertex) + " / tet object " +
                        std::to_string(c.tet_object) + " out of range");
        s.need[static_cast<size_t>(c.tet_object)] = 1;
    }
    PenetrationStats st;
    s.update_trees(x, st);
    std::vector<double> out(contacts.size(), 0.0);
    for (size_t c = 0; c < contacts.size(); ++c) {
        Vec3 point;
        double dist = 0;
        if (s.closest(x, s.trees[static_cast<size_t>(contacts[c].tet_object)], contacts[c].vertex, point, dist))
            out[c] = dist;
    }
    return out;
}

void compute_penetration(const TetMesh& mesh, std::span<Contact> contacts, PenetrationStats* stats)
{
    Penetration p;
    p.set_topology(mesh);
    p.compute(mesh.positions, contacts, stats);
}

} // namespace tethash
