#include "lattice.hpp"

#include "tethash/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace tethash::meshing::detail {

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

} // namespace tethash::meshing::detail
