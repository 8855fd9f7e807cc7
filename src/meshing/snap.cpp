#include "snap.hpp"

#include "parallel.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace tethash::meshing::detail {

namespace {

using Vec3 = Eigen::Vector3d;

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

} // namespace

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

} // namespace tethash::meshing::detail
