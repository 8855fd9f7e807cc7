#include "tethash/meshing/winding_number.hpp"

#include "parallel.hpp"
#include "surface_tree.hpp"

namespace tethash::meshing {

std::vector<double> winding_numbers(const SurfaceMesh& surface, const std::vector<Eigen::Vector3d>& points)
{
    detail::check_surface(surface);
    const detail::SurfaceTree tree(surface);
    std::vector<double> w(points.size());
    TETHASH_OMP("omp parallel for schedule(dynamic, 256)")
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(points.size()); ++i)
        w[static_cast<std::size_t>(i)] = tree.winding(points[static_cast<std::size_t>(i)]);
    return w;
}

} // namespace tethash::meshing
