#include "surface_tree.hpp"

#include "tethash/error.hpp"

#include <string>

namespace tethash::meshing::detail {

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

} // namespace tethash::meshing::detail
