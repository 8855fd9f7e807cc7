// BCC-lattice tetrahedralization of an implicit inside (signed-distance function or closed surface),
// with boundary snapping that never inverts or flattens a tet. See io/generate.hpp.
#include "tethash/io/generate.hpp"

#include "tethash/error.hpp"
#include "tethash/geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#ifdef _OPENMP
#define TETHASH_OMP(directive) _Pragma(directive)
#else
#define TETHASH_OMP(directive)
#endif

namespace tethash::io {

namespace {

using Vec3 = Eigen::Vector3d;

// ---- the lattice ----------------------------------------------------------------------------

/// Cube centres at origin + i*h (i = 0..nc-1 per axis); cube corners at origin + (i - 1/2)*h
/// (i = 0..nc per axis). Corner ids come first, then centre ids, both x-fastest.
struct Lattice {
    Vec3 origin;
    Vec3 h;
    std::array<int, 3> nc{};

    std::int64_t corner_id(int i, int j, int k) const
    {
        return i + std::int64_t(nc[0] + 1) * (j + std::int64_t(nc[1] + 1) * k);
    }
    std::int64_t num_corners() const { return std::int64_t(nc[0] + 1) * (nc[1] + 1) * (nc[2] + 1); }
    std::int64_t centre_id(int i, int j, int k) const
    {
        return num_corners() + i + std::int64_t(nc[0]) * (j + std::int64_t(nc[1]) * k);
    }
    std::int64_t num_vertices() const { return num_corners() + std::int64_t(nc[0]) * nc[1] * nc[2]; }
    Vec3 position(std::int64_t id) const
    {
        const bool centre = id >= num_corners();
        std::int64_t r = centre ? id - num_corners() : id;
        const std::int64_t sx = centre ? nc[0] : nc[0] + 1, sy = centre ? nc[1] : nc[1] + 1;
        const double i = double(r % sx), j = double((r / sx) % sy), k = double(r / (sx * sy));
        const double off = centre ? 0.0 : -0.5;
        return origin + Vec3((i + off) * h.x(), (j + off) * h.y(), (k + off) * h.z());
    }
};

/// Lattice over box_min..box_max with `resolution` cells along the longest extent. Each axis gets
/// its own spacing h_a = L_a / (k_a + 1/4) so that both box faces lie h_a/8 outside the nearest
/// cube-centre plane: then the tets kept by the centroid test at a flat face have their centres just
/// inside and corners outside, and snapping a box face flattens no tet (no ties at the faces either).
Lattice make_lattice(const Vec3& box_min, const Vec3& box_max, int resolution)
{
    if (resolution < 1 || resolution > 1000)
        throw Error("resolution " + std::to_string(resolution) + " out of range (expected 1..1000)");
    const Vec3 ext = box_max - box_min;
    if (!ext.allFinite() || ext.minCoeff() <= 0)
        throw Error("bounding box for tetrahedralization is empty or not finite");
    const double h0 = ext.maxCoeff() / (resolution + 0.25);
    Lattice lat;
    for (int a = 0; a < 3; ++a) {
        const int k = std::max(1, static_cast<int>(std::lround(ext[a] / h0 - 0.25)));
        lat.h[a] = ext[a] / (k + 0.25);
        lat.nc[a] = k + 3; // k+1 centre planes inside the box, one outside on each side
        lat.origin[a] = box_min[a] + lat.h[a] / 8 - lat.h[a];
    }
    return lat;
}

/// Every tet of the lattice, each positively oriented, in a fixed order.
std::vector<std::array<std::int64_t, 4>> lattice_tets(const Lattice& lat)
{
    std::vector<std::array<std::int64_t, 4>> tets;
    std::int64_t count = 0;
    for (int a = 0; a < 3; ++a) {
        std::int64_t c = 4;
        for (int b = 0; b < 3; ++b)
            c *= (b == a ? lat.nc[b] - 1 : lat.nc[b]);
        count += c;
    }
    if (count > std::numeric_limits<Index>::max())
        throw Error("resolution too high: the lattice has " + std::to_string(count) +
                    " tets, more than tet indices (int32) can count");
    tets.reserve(static_cast<std::size_t>(count));
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, d = (a + 2) % 3;
        for (int k = 0; k < lat.nc[2]; ++k)
            for (int j = 0; j < lat.nc[1]; ++j)
                for (int i = 0; i < lat.nc[0]; ++i) {
                    std::array<int, 3> c0{i, j, k};
                    if (c0[a] + 1 >= lat.nc[a]) continue;
                    std::array<int, 3> c1 = c0;
                    c1[a] += 1;
                    // Corners of the shared face: corner index c0[a]+1 along a; c0[b]+{0,1}, c0[d]+{0,1}.
                    auto corner = [&](int db, int dd) {
                        std::array<int, 3> q{};
                        q[a] = c0[a] + 1;
                        q[b] = c0[b] + db;
                        q[d] = c0[d] + dd;
                        return lat.corner_id(q[0], q[1], q[2]);
                    };
                    const std::array<std::int64_t, 4> ring{corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)};
                    const std::int64_t ca = lat.centre_id(c0[0], c0[1], c0[2]);
                    const std::int64_t cb = lat.centre_id(c1[0], c1[1], c1[2]);
                    for (int e = 0; e < 4; ++e) {
                        std::array<std::int64_t, 4> t{ca, cb, ring[e], ring[(e + 1) % 4]};
                        const Vec3 p0 = lat.position(t[0]), p1 = lat.position(t[1]), p2 = lat.position(t[2]),
                                   p3 = lat.position(t[3]);
                        if ((p1 - p0).dot((p2 - p0).cross(p3 - p0)) < 0) std::swap(t[2], t[3]);
                        tets.push_back(t);
                    }
                }
    }
    return tets;
}

double signed_vol(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
{
    return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

/// Smallest dihedral angle (degrees) of a tet; 0 for a degenerate one.
double min_dihedral(const Vec3 x[4])
{
    static constexpr int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    Vec3 n[4];
    for (int f = 0; f < 4; ++f) {
        n[f] = (x[face[f][1]] - x[face[f][0]]).cross(x[face[f][2]] - x[face[f][0]]);
        const double len = n[f].norm();
        if (!(len > 0)) return 0.0;
        n[f] /= len;
    }
    double best = 180.0;
    for (int f = 0; f < 4; ++f)
        for (int g = f + 1; g < 4; ++g) {
            const double c = std::clamp(n[f].dot(n[g]), -1.0, 1.0);
            best = std::min(best, 180.0 - std::acos(c) * 180.0 / std::numbers::pi);
        }
    return best;
}

/// Makes the boundary of the kept set a manifold: adds every lattice tet around a boundary edge used
/// by more than two boundary faces, and around a boundary vertex whose boundary faces form more than
/// one fan (two parts touching at a vertex), until none is left (or a few rounds passed). `keep` is
/// indexed like `all`.
void repair_nonmanifold(const std::vector<std::array<std::int64_t, 4>>& all, std::vector<char>& keep)
{
    using Face = std::array<std::int64_t, 3>;
    for (int round = 0; round < 8; ++round) {
        // Boundary faces of the kept set.
        std::vector<Face> faces;
        for (std::size_t t = 0; t < all.size(); ++t) {
            if (!keep[t]) continue;
            for (int f = 0; f < 4; ++f) {
                Face fc;
                int m = 0;
                for (int v = 0; v < 4; ++v)
                    if (v != f) fc[m++] = all[t][v];
                std::sort(fc.begin(), fc.end());
                faces.push_back(fc);
            }
        }
        std::sort(faces.begin(), faces.end());
        std::vector<Face> boundary;
        for (std::size_t i = 0; i < faces.size();) {
            std::size_t j = i;
            while (j < faces.size() && faces[j] == faces[i])
                ++j;
            if (j - i == 1) boundary.push_back(faces[i]);
            i = j;
        }
        faces.clear();
        std::vector<std::pair<std::int64_t, std::int64_t>> edges;
        for (const Face& v : boundary) {
            edges.push_back({v[0], v[1]});
            edges.push_back({v[0], v[2]});
            edges.push_back({v[1], v[2]});
        }
        std::sort(edges.begin(), edges.end());
        std::vector<std::pair<std::int64_t, std::int64_t>> bad_edges;
        for (std::size_t i = 0; i < edges.size();) {
            std::size_t j = i;
            while (j < edges.size() && edges[j] == edges[i])
                ++j;
            if (j - i > 2) bad_edges.push_back(edges[i]);
            i = j;
        }
        // Fans: per vertex, the boundary faces around it joined when they share an edge at the vertex.
        std::vector<std::pair<std::int64_t, std::size_t>> incident; // (vertex, boundary face)
        for (std::size_t f = 0; f < boundary.size(); ++f)
            for (auto v : boundary[f])
                incident.push_back({v, f});
        std::sort(incident.begin(), incident.end());
        std::vector<std::int64_t> bad_vertices;
        std::vector<int> parent;
        for (std::size_t i = 0; i < incident.size();) {
            std::size_t j = i;
            while (j < incident.size() && incident[j].first == incident[i].first)
                ++j;
            const std::int64_t v = incident[i].first;
            const std::size_t n = j - i;
            parent.resize(n);
            for (std::size_t a = 0; a < n; ++a)
                parent[a] = static_cast<int>(a);
            auto find = [&](int x) {
                while (parent[static_cast<std::size_t>(x)] != x)
                    x = parent[static_cast<std::size_t>(x)] =
                        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
                return x;
            };
            for (std::size_t a = 0; a < n; ++a)
                for (std::size_t b = a + 1; b < n; ++b) {
                    const Face& fa = boundary[incident[i + a].second];
                    const Face& fb = boundary[incident[i + b].second];
                    bool share = false;
                    for (auto x : fa)
                        if (x != v && std::find(fb.begin(), fb.end(), x) != fb.end()) share = true;
                    if (share) parent[static_cast<std::size_t>(find(static_cast<int>(a)))] = find(static_cast<int>(b));
                }
            int fans = 0;
            for (std::size_t a = 0; a < n; ++a)
                if (find(static_cast<int>(a)) == static_cast<int>(a)) ++fans;
            if (fans > 1) bad_vertices.push_back(v);
            i = j;
        }
        if (bad_edges.empty() && bad_vertices.empty()) return;
        // Fill every lattice tet around each bad edge and each bad vertex.
        for (std::size_t t = 0; t < all.size(); ++t) {
            if (keep[t]) continue;
            const auto& q = all[t];
            for (int x = 0; x < 4 && !keep[t]; ++x) {
                if (std::binary_search(bad_vertices.begin(), bad_vertices.end(), q[x])) keep[t] = 1;
                for (int y = x + 1; y < 4 && !keep[t]; ++y) {
                    const std::pair<std::int64_t, std::int64_t> e{std::min(q[x], q[y]), std::max(q[x], q[y])};
                    if (std::binary_search(bad_edges.begin(), bad_edges.end(), e)) keep[t] = 1;
                }
            }
        }
    }
}

/// Moves boundary vertices toward `target(p)` (nullopt-like: returns false when there is none),
/// one vertex at a time, as far as keeps every incident tet at ≥ kMinVolumeFraction of its lattice
/// volume and ≥ kMinDihedral degrees. Two sweeps; deterministic (vertex order).
void snap_boundary(TetMesh& mesh, const std::function<bool(const Vec3&, Vec3&)>& target, double max_move)
{
    constexpr double kMinVolumeFraction = 0.2;
    constexpr double kMinDihedral = 10.0;
    const Index n = mesh.num_vertices();
    const Triangles bf = boundary_faces(mesh.tets);
    std::vector<char> on_boundary(static_cast<std::size_t>(n), 0);
    for (Eigen::Index i = 0; i < bf.rows(); ++i)
        for (int k = 0; k < 3; ++k)
            on_boundary[static_cast<std::size_t>(bf(i, k))] = 1;
    std::vector<Index> verts;
    for (Index v = 0; v < n; ++v)
        if (on_boundary[static_cast<std::size_t>(v)]) verts.push_back(v);
    const Adjacency inc = vertex_tets(mesh.tets, n);
    std::vector<double> vol0(static_cast<std::size_t>(mesh.num_tets()));
    auto P = [&](Index v) -> Vec3 { return mesh.positions.row(v).transpose(); };
    for (Index t = 0; t < mesh.num_tets(); ++t)
        vol0[static_cast<std::size_t>(t)] =
            signed_vol(P(mesh.tets(t, 0)), P(mesh.tets(t, 1)), P(mesh.tets(t, 2)), P(mesh.tets(t, 3)));

    std::vector<Vec3> goal(verts.size());
    std::vector<char> has_goal(verts.size(), 0);
    for (int sweep = 0; sweep < 2; ++sweep) {
        // Targets depend only on the vertex's own position: compute them in parallel.
        TETHASH_OMP("omp parallel for schedule(dynamic, 64)")
        for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(verts.size()); ++i) {
            Vec3 g;
            has_goal[static_cast<std::size_t>(i)] = target(P(verts[static_cast<std::size_t>(i)]), g) ? 1 : 0;
            goal[static_cast<std::size_t>(i)] = g;
        }
        for (std::size_t i = 0; i < verts.size(); ++i) {
            if (!has_goal[i]) continue;
            const Index v = verts[i];
            const Vec3 p = P(v);
            Vec3 d = goal[i] - p;
            if (!d.allFinite()) continue;
            const double len = d.norm();
            if (len <= 0) continue;
            if (len > max_move) d *= max_move / len;
            for (double s : {1.0, 0.5, 0.25}) {
                const Vec3 q = p + s * d;
                bool ok = true;
                for (Index k = inc.offsets[static_cast<std::size_t>(v)];
                     ok && k < inc.offsets[static_cast<std::size_t>(v) + 1]; ++k) {
                    const Index t = inc.neighbours[static_cast<std::size_t>(k)];
                    Vec3 x[4];
                    for (int c = 0; c < 4; ++c)
                        x[c] = mesh.tets(t, c) == v ? q : P(mesh.tets(t, c));
                    const double vol = signed_vol(x[0], x[1], x[2], x[3]);
                    if (!(vol >= kMinVolumeFraction * vol0[static_cast<std::size_t>(t)]) ||
                        min_dihedral(x) < kMinDihedral)
                        ok = false;
                }
                if (ok) {
                    mesh.positions.row(v) = q.transpose();
                    break;
                }
            }
        }
    }
}

/// The lattice tets whose centroid `inside` accepts, compacted and renumbered (lattice order), then
/// snapped with `target` when given.
TetMesh build(const Lattice& lat, const std::function<std::vector<char>(const std::vector<Vec3>&)>& inside,
              const std::function<bool(const Vec3&, Vec3&)>* target)
{
    const auto all = lattice_tets(lat);
    std::vector<Vec3> centroids(all.size());
    TETHASH_OMP("omp parallel for schedule(static)")
    for (std::ptrdiff_t t = 0; t < static_cast<std::ptrdiff_t>(all.size()); ++t) {
        const auto& q = all[static_cast<std::size_t>(t)];
        centroids[static_cast<std::size_t>(t)] =
            0.25 * (lat.position(q[0]) + lat.position(q[1]) + lat.position(q[2]) + lat.position(q[3]));
    }
    std::vector<char> keep = inside(centroids);
    centroids.clear();
    centroids.shrink_to_fit();
    if (std::none_of(keep.begin(), keep.end(), [](char c) { return c != 0; }))
        throw Error("nothing is inside the shape at this resolution (is the surface closed? try a higher resolution)");
    repair_nonmanifold(all, keep);

    std::vector<Index> new_id(static_cast<std::size_t>(lat.num_vertices()), -1);
    std::int64_t kept_tets = 0;
    for (std::size_t t = 0; t < all.size(); ++t)
        if (keep[t]) {
            ++kept_tets;
            for (auto v : all[t])
                new_id[static_cast<std::size_t>(v)] = 0;
        }
    Index nv = 0;
    for (auto& id : new_id)
        if (id == 0) id = nv++;
    TetMesh mesh;
    mesh.positions.resize(nv, 3);
    for (std::int64_t v = 0; v < lat.num_vertices(); ++v)
        if (new_id[static_cast<std::size_t>(v)] >= 0)
            mesh.positions.row(new_id[static_cast<std::size_t>(v)]) = lat.position(v).transpose();
    mesh.tets.resize(static_cast<Eigen::Index>(kept_tets), 4);
    Eigen::Index row = 0;
    for (std::size_t t = 0; t < all.size(); ++t)
        if (keep[t]) {
            for (int c = 0; c < 4; ++c)
                mesh.tets(row, c) = new_id[static_cast<std::size_t>(all[t][c])];
            ++row;
        }
    if (target) snap_boundary(mesh, *target, 0.75 * lat.h.maxCoeff());
    return mesh;
}

// ---- surfaces: bounding-volume hierarchy for winding numbers and closest points -------------

class SurfaceTree {
  public:
    explicit SurfaceTree(const SurfaceMesh& s) : m_s(s)
    {
        const auto nt = static_cast<std::size_t>(s.triangles.rows());
        m_order.resize(nt);
        m_centroid.resize(nt);
        for (std::size_t t = 0; t < nt; ++t) {
            m_order[t] = static_cast<int>(t);
            m_centroid[t] = (vertex(t, 0) + vertex(t, 1) + vertex(t, 2)) / 3.0;
        }
        m_nodes.reserve(2 * nt / kLeaf + 2);
        if (nt > 0) build(0, static_cast<int>(nt));
    }

    /// Generalized winding number at q.
    double winding(const Vec3& q) const
    {
        double w = 0;
        int stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& nd = m_nodes[static_cast<std::size_t>(stack[--top])];
            const Vec3 r = nd.centre - q;
            const double dist = r.norm();
            if (dist > kBeta * nd.radius) {
                w += r.dot(nd.area) / (dist * dist * dist);
                continue;
            }
            if (nd.left < 0) {
                for (int i = nd.begin; i < nd.end; ++i) {
                    const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
                    w += solid_angle(vertex(t, 0) - q, vertex(t, 1) - q, vertex(t, 2) - q);
                }
            } else {
                stack[top++] = nd.left;
                stack[top++] = nd.right;
            }
        }
        return w / (4.0 * std::numbers::pi);
    }

    /// Closest point of the surface to q.
    Vec3 closest(const Vec3& q) const
    {
        double best = std::numeric_limits<double>::infinity();
        Vec3 best_p = q;
        int stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& nd = m_nodes[static_cast<std::size_t>(stack[--top])];
            if (nd.box.squaredExteriorDistance(q) >= best) continue;
            if (nd.left < 0) {
                for (int i = nd.begin; i < nd.end; ++i) {
                    const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
                    const Vec3 c = closest_point_on_triangle(q, vertex(t, 0), vertex(t, 1), vertex(t, 2));
                    const double d2 = (c - q).squaredNorm();
                    if (d2 < best) {
                        best = d2;
                        best_p = c;
                    }
                }
            } else {
                const Node& l = m_nodes[static_cast<std::size_t>(nd.left)];
                const Node& r = m_nodes[static_cast<std::size_t>(nd.right)];
                // Visit the nearer child first (pushed last).
                if (l.box.squaredExteriorDistance(q) < r.box.squaredExteriorDistance(q)) {
                    stack[top++] = nd.right;
                    stack[top++] = nd.left;
                } else {
                    stack[top++] = nd.left;
                    stack[top++] = nd.right;
                }
            }
        }
        return best_p;
    }

  private:
    static constexpr int kLeaf = 8;
    static constexpr double kBeta = 2.0; ///< far field when distance > kBeta × node radius

    struct Node {
        Eigen::AlignedBox3d box;
        Vec3 centre = Vec3::Zero(); ///< area-weighted centroid of the node's triangles
        Vec3 area = Vec3::Zero();   ///< sum of area vectors (½ (b-a)×(c-a))
        double radius = 0;          ///< max distance from centre to a triangle vertex
        int left = -1, right = -1, begin = 0, end = 0;
    };

    Vec3 vertex(std::size_t t, int k) const
    {
        return m_s.vertices.row(m_s.triangles(static_cast<Eigen::Index>(t), k)).transpose();
    }

    int build(int begin, int end)
    {
        const int id = static_cast<int>(m_nodes.size());
        m_nodes.emplace_back();
        Node nd;
        nd.begin = begin;
        nd.end = end;
        Eigen::AlignedBox3d cbox;
        double total_area = 0;
        Vec3 weighted = Vec3::Zero();
        for (int i = begin; i < end; ++i) {
            const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
            const Vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
            nd.box.extend(a);
            nd.box.extend(b);
            nd.box.extend(c);
            cbox.extend(m_centroid[t]);
            const Vec3 av = 0.5 * (b - a).cross(c - a);
            nd.area += av;
            const double ar = av.norm();
            total_area += ar;
            weighted += ar * m_centroid[t];
        }
        nd.centre = total_area > 0 ? Vec3(weighted / total_area) : nd.box.center();
        for (int i = begin; i < end; ++i) {
            const auto t = static_cast<std::size_t>(m_order[static_cast<std::size_t>(i)]);
            for (int k = 0; k < 3; ++k)
                nd.radius = std::max(nd.radius, (vertex(t, k) - nd.centre).norm());
        }
        if (end - begin > kLeaf) {
            int axis = 0;
            cbox.sizes().maxCoeff(&axis);
            const int mid = (begin + end) / 2;
            std::nth_element(m_order.begin() + begin, m_order.begin() + mid, m_order.begin() + end, [&](int x, int y) {
                const double cx = m_centroid[static_cast<std::size_t>(x)][axis];
                const double cy = m_centroid[static_cast<std::size_t>(y)][axis];
                return cx < cy || (cx == cy && x < y);
            });
            nd.left = build(begin, mid);
            nd.right = build(mid, end);
        }
        m_nodes[static_cast<std::size_t>(id)] = nd;
        return id;
    }

    /// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom and Strackee).
    static double solid_angle(const Vec3& a, const Vec3& b, const Vec3& c)
    {
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double num = a.dot(b.cross(c));
        const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        return 2.0 * std::atan2(num, den);
    }

    const SurfaceMesh& m_s;
    std::vector<Node> m_nodes;
    std::vector<int> m_order;
    std::vector<Vec3> m_centroid;
};

void check_surface(const SurfaceMesh& s)
{
    if (s.triangles.rows() == 0) throw Error("surface has no triangles");
    const Index nv = static_cast<Index>(s.vertices.rows());
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
        for (int k = 0; k < 3; ++k)
            if (s.triangles(t, k) < 0 || s.triangles(t, k) >= nv)
                throw Error("surface triangle " + std::to_string(t) + " has vertex index " +
                            std::to_string(s.triangles(t, k)) + " out of range (0.." + std::to_string(nv - 1) + ")");
    if (!s.vertices.allFinite()) throw Error("surface has a non-finite vertex coordinate");
}

} // namespace

TetMesh
tetrahedralize_sdf(const std::function<double(const Eigen::Vector3d&)>& sdf, const Eigen::Vector3d& box_min,
                   const Eigen::Vector3d& box_max, int resolution, bool snap,
                   const std::function<Eigen::Vector3d(const Eigen::Vector3d&, const Eigen::Vector3d&)>& project)
{
    const Lattice lat = make_lattice(box_min, box_max, resolution);
    auto inside = [&](const std::vector<Vec3>& pts) {
        std::vector<char> in(pts.size());
        TETHASH_OMP("omp parallel for schedule(static)")
        for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(pts.size()); ++i)
            in[static_cast<std::size_t>(i)] = sdf(pts[static_cast<std::size_t>(i)]) < 0 ? 1 : 0;
        return in;
    };
    const double hmin = lat.h.minCoeff();
    std::function<bool(const Vec3&, Vec3&)> target = [&](const Vec3& p, Vec3& out) {
        if (project) {
            out = project(p, lat.h);
            return out.allFinite();
        }
        // Newton steps along the gradient (central differences) onto the zero level set.
        const double eps = 1e-4 * hmin;
        Vec3 x = p;
        for (int it = 0; it < 12; ++it) {
            const double f = sdf(x);
            if (!std::isfinite(f)) return false;
            if (std::abs(f) < 1e-9 * hmin) break;
            Vec3 g;
            for (int a = 0; a < 3; ++a) {
                Vec3 e = Vec3::Zero();
                e[a] = eps;
                g[a] = (sdf(x + e) - sdf(x - e)) / (2 * eps);
            }
            const double g2 = g.squaredNorm();
            if (!(g2 > 1e-12)) return false;
            x -= (f / g2) * g;
        }
        out = x;
        return true;
    };
    return build(lat, inside, snap ? &target : nullptr);
}

std::vector<double> winding_numbers(const SurfaceMesh& surface, const std::vector<Eigen::Vector3d>& points)
{
    check_surface(surface);
    const SurfaceTree tree(surface);
    std::vector<double> w(points.size());
    TETHASH_OMP("omp parallel for schedule(dynamic, 256)")
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(points.size()); ++i)
        w[static_cast<std::size_t>(i)] = tree.winding(points[static_cast<std::size_t>(i)]);
    return w;
}

TetMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeParams& params)
{
    check_surface(surface);
    Vec3 lo = surface.vertices.colwise().minCoeff().transpose();
    Vec3 hi = surface.vertices.colwise().maxCoeff().transpose();
    const Lattice lat = make_lattice(lo, hi, params.resolution);
    const SurfaceTree tree(surface);
    auto inside = [&](const std::vector<Vec3>& pts) {
        std::vector<char> in(pts.size());
        TETHASH_OMP("omp parallel for schedule(dynamic, 256)")
        for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(pts.size()); ++i) {
            const Vec3& p = pts[static_cast<std::size_t>(i)];
            // Outside the bounding box the winding number of a (nearly) closed surface is ~0.
            const bool in_box = (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
            in[static_cast<std::size_t>(i)] = in_box && std::abs(tree.winding(p)) > 0.5 ? 1 : 0;
        }
        return in;
    };
    std::function<bool(const Vec3&, Vec3&)> target = [&](const Vec3& p, Vec3& out) {
        out = tree.closest(p);
        return true;
    };
    try {
        return build(lat, inside, params.snap ? &target : nullptr);
    } catch (const Error& e) {
        throw Error(std::string("surface to tetrahedralize: ") + e.what());
    }
}

} // namespace tethash::io
