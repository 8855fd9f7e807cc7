#pragma once
// Private to tethash::meshing: the body-centred-cubic lattice every generated mesh is cut from.
#include "tethash/mesh.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace tethash::meshing::detail {

using Vec3 = Eigen::Vector3d;

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
/// Throws Error for resolution < 1 or > 1000 or an empty box.
Lattice make_lattice(const Vec3& box_min, const Vec3& box_max, int resolution);

/// Every tet of the lattice, each positively oriented, in a fixed order.
std::vector<std::array<std::int64_t, 4>> lattice_tets(const Lattice& lat);

} // namespace tethash::meshing::detail
