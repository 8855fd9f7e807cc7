// BCC-lattice tetrahedralization of an implicit inside (signed-distance function or closed surface),
// with boundary snapping that never inverts or flattens a tet. See meshing/tetrahedralize.hpp.
#include "tethash/meshing/tetrahedralize.hpp"

#include "lattice.hpp"
#include "parallel.hpp"
#include "repair.hpp"
#include "snap.hpp"
#include "surface_tree.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace tethash::meshing {

using namespace detail;

namespace {

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

} // namespace tethash::meshing
