// The scenes of the space-partition comparison (scenarios.hpp: partition_scene).
#include "tethash/error.hpp"
#include "tethash/study/scenarios.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>

namespace tethash::study {

namespace {

/// splitmix64 (as scenarios.cpp): the same scenes with every standard library.
struct Rng {
    std::uint64_t state;
    double uniform()
    {
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        z ^= z >> 31;
        return static_cast<double>(z >> 11) * (1.0 / 9007199254740992.0);
    }
    /// A uniform random rotation (Shoemake).
    Eigen::Matrix3d rotation()
    {
        const double u1 = uniform(), u2 = uniform() * 2 * M_PI, u3 = uniform() * 2 * M_PI;
        const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(u3), std::sqrt(1 - u1) * std::sin(u2),
                                   std::sqrt(1 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));
        return q.normalized().toRotationMatrix();
    }
};

/// `object` rotated by `r` about its box centre, which is moved to `centre`, appended to `scene` as a new object.
void place(TetMesh& scene, const TetMesh& object, const Eigen::Matrix3d& r, const Eigen::Vector3d& centre)
{
    const auto [lo, hi] = bounding_box(object.positions);
    const Eigen::Vector3d mid = 0.5 * (lo + hi);
    TetMesh copy;
    copy.tets = object.tets;
    copy.positions.resize(object.positions.rows(), 3);
    for (Eigen::Index v = 0; v < object.positions.rows(); ++v)
        copy.positions.row(v) = (r * (object.positions.row(v).transpose() - mid) + centre).transpose();
    if (scene.num_tets() == 0) {
        scene = std::move(copy);
        scene.ensure_object_ids();
    } else {
        scene.append(copy);
    }
}

/// "rI_J", the name of room (i, j).
std::string fmt_room(int i, int j)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "r%d_%d", i, j);
    return buf;
}

Eigen::Vector3d random_point(Rng& rng, const Eigen::Vector3d& lo, double width)
{
    return lo + width * Eigen::Vector3d(rng.uniform(), rng.uniform(), rng.uniform());
}

} // namespace

TetMesh cube_lattice(int nx, int ny, int nz, const Eigen::Vector3d& h)
{
    TetMesh m;
    const auto id = [&](int i, int j, int k) { return static_cast<Index>((k * (ny + 1) + j) * (nx + 1) + i); };
    m.positions.resize(static_cast<Eigen::Index>(nx + 1) * (ny + 1) * (nz + 1), 3);
    for (int k = 0; k <= nz; ++k)
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i)
                m.positions.row(id(i, j, k)) << i * h.x(), j * h.y(), k * h.z();
    // Kuhn's six tets around the diagonal from corner 0 to corner 7 (corner bits: x 1, y 2, z 4).
    static const int paths[6][2] = {{1, 3}, {2, 3}, {2, 6}, {4, 6}, {4, 5}, {1, 5}};
    m.tets.resize(6 * static_cast<Eigen::Index>(nx) * ny * nz, 4);
    Eigen::Index t = 0;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const auto corner = [&](int c) { return id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)); };
                for (const auto& p : paths) {
                    std::array<Index, 4> tet = {corner(0), corner(p[0]), corner(p[1]), corner(7)};
                    if (signed_volume(m.positions, tet) < 0) std::swap(tet[1], tet[2]);
                    m.tets.row(t++) << tet[0], tet[1], tet[2], tet[3];
                }
            }
    m.ensure_object_ids();
    return m;
}

ObstacleSet building_walls(int nx, int ny)
{
    if (nx < 1 || ny < 1) throw Error("building_walls: expected at least one room per axis");
    constexpr double room = 4, height = 3, door = 1, door_height = 2, half = 0.05;
    ObstacleSet set;
    // A box's closed surface: corner k is (k & 1, k & 2, k & 4) of (lo, hi); two outward triangles per face.
    static const int faces[12][3] = {{0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}, {0, 4, 5}, {0, 5, 1},
                                     {2, 3, 7}, {2, 7, 6}, {0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}};
    const int count[2] = {nx, ny};
    for (int axis = 0; axis < 2; ++axis) {
        const int other = 1 - axis;
        for (int i = 0; i <= count[axis]; ++i) {
            auto wall = [&](double from, double to, double z0, double z1) {
                Eigen::Vector3d lo, hi;
                lo[axis] = room * i - half, hi[axis] = room * i + half;
                lo[other] = from, hi[other] = to;
                lo[2] = z0, hi[2] = z1;
                Positions v(8, 3);
                for (int k = 0; k < 8; ++k)
                    v.row(k) << (k & 1 ? hi.x() : lo.x()), (k & 2 ? hi.y() : lo.y()), (k & 4 ? hi.z() : lo.z());
                Triangles t(12, 3);
                for (int f = 0; f < 12; ++f)
                    t.row(f) << faces[f][0], faces[f][1], faces[f][2];
                set.add(Bsp(v, t, "building wall"));
            };
            const double end = room * count[other] + half;
            if (i == 0 || i == count[axis]) {
                wall(-half, end, 0, height);
                continue;
            }
            double from = -half;
            for (int j = 0; j < count[other]; ++j) {
                const double mid = room * (j + 0.5);
                wall(from, mid - 0.5 * door, 0, height);
                wall(mid - 0.5 * door, mid + 0.5 * door, door_height, height);
                from = mid + 0.5 * door;
            }
            wall(from, end, 0, height);
        }
    }
    return set;
}

NamedScene building_scene(int nx, int ny, std::uint64_t seed)
{
    if (nx < 1 || ny < 1) throw Error("building_scene: expected at least one room per axis");
    constexpr double room = 4, height = 3, door = 1, door_height = 2, margin = 0.4;
    NamedScene s;
    s.name = "building";
    s.description = std::to_string(nx * ny) + " rooms (" + std::to_string(nx) + " x " + std::to_string(ny) +
                    ", 4 x 4 x 3) joined by doors, 5 pairs of overlapping 3^3-cube objects (edge 0.1) in each room "
                    "and one pair in each doorway";
    Rng rng{seed};
    auto layout = std::make_shared<CellLayout>();
    const auto index = [&](int i, int j) { return static_cast<Index>(i * ny + j); };
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j) {
            PortalCell c;
            c.name = fmt_room(i, j);
            c.lo[0] = room * i, c.lo[1] = room * j, c.lo[2] = 0;
            c.hi[0] = room * (i + 1), c.hi[1] = room * (j + 1), c.hi[2] = height;
            layout->cells.push_back(c);
        }
    const TetMesh object = cube_lattice(3, 3, 3, Eigen::Vector3d::Constant(0.1));
    // A pair: two objects, the second moved by about a third of the object's size, so that they overlap.
    const auto pair = [&](const Eigen::Vector3d& at) {
        place(s.mesh, object, rng.rotation(), at);
        const Eigen::Vector3d shift(0.1 + 0.05 * rng.uniform(), 0.1 * rng.uniform(), 0.1 * rng.uniform());
        place(s.mesh, object, rng.rotation(), at + shift);
    };
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j) {
            const Eigen::Vector3d lo(room * i + margin, room * j + margin, margin);
            for (int k = 0; k < 5; ++k)
                pair(lo + Eigen::Vector3d(rng.uniform() * (room - 2 * margin), rng.uniform() * (room - 2 * margin),
                                          rng.uniform() * (height - 2 * margin)));
        }
    // Doors: between (i, j) and (i + 1, j) in the wall x = 4(i + 1), between (i, j) and (i, j + 1) in y = 4(j + 1).
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j)
            for (int axis = 0; axis < 2; ++axis) {
                if ((axis == 0 && i + 1 >= nx) || (axis == 1 && j + 1 >= ny)) continue;
                Portal p;
                p.a = index(i, j);
                p.b = axis == 0 ? index(i + 1, j) : index(i, j + 1);
                const double wall = room * ((axis == 0 ? i : j) + 1), across = room * ((axis == 0 ? j : i) + 0.5);
                const int other = 1 - axis;
                p.lo[axis] = p.hi[axis] = wall;
                p.lo[other] = across - 0.5 * door;
                p.hi[other] = across + 0.5 * door;
                p.lo[2] = 0;
                p.hi[2] = door_height;
                layout->portals.push_back(p);
                Eigen::Vector3d at;
                at[axis] = wall - 0.05;
                at[other] = across - 0.1;
                at[2] = 0.5 + rng.uniform();
                pair(at);
            }
    check_cell_layout(*layout);
    s.cells = layout;
    s.walls = std::make_shared<const ObstacleSet>(building_walls(nx, ny));
    return s;
}

const std::vector<std::string>& partition_scene_names()
{
    static const std::vector<std::string> names = {"bars", "sizes", "corner", "thin", "building", "walled", "hall"};
    return names;
}

NamedScene partition_scene(const std::string& name)
{
    NamedScene s;
    s.name = name;
    std::uint64_t seed = 0x5ca1ab1eULL;
    for (char c : name)
        seed = seed * 131 + static_cast<unsigned char>(c);
    Rng rng{seed};
    const Eigen::Matrix3d id = Eigen::Matrix3d::Identity();
    if (name == "bars") {
        s.description = "100 bars of 1 x 2 x 42 cubes (six tets each) in random directions, crossing in a box 30 long";
        const TetMesh bar = cube_lattice(1, 2, 42, Eigen::Vector3d::Ones());
        for (int o = 0; o < 100; ++o)
            place(s.mesh, bar, rng.rotation(), random_point(rng, Eigen::Vector3d::Zero(), 30));
    } else if (name == "sizes") {
        s.description = "tet sizes spanning three decades: a 4^3-cube object of edge 1 and, overlapping it, 3 of "
                        "edge 0.1, 10 of edge 0.01 and 60 of edge 0.001";
        place(s.mesh, cube_lattice(4, 4, 4, Eigen::Vector3d::Constant(1)), id, Eigen::Vector3d::Constant(2));
        for (const auto& [count, edge] : {std::pair{3, 0.1}, std::pair{10, 0.01}, std::pair{60, 0.001}})
            for (int o = 0; o < count; ++o)
                place(s.mesh, cube_lattice(4, 4, 4, Eigen::Vector3d::Constant(edge)), rng.rotation(),
                      random_point(rng, Eigen::Vector3d::Zero(), 4));
    } else if (name == "corner") {
        s.description = "60 overlapping 4^3-cube objects (edge 0.05) in a corner 0.7 wide of a domain 16 wide";
        const TetMesh cube = cube_lattice(4, 4, 4, Eigen::Vector3d::Constant(0.05));
        for (int o = 0; o < 60; ++o)
            place(s.mesh, cube, rng.rotation(), random_point(rng, Eigen::Vector3d::Constant(0.1), 0.5));
        place(s.mesh, cube, id, Eigen::Vector3d::Constant(15.9));
    } else if (name == "thin") {
        s.description = "12 objects of 2 x 20 x 20 cubes of 1 x 0.1 x 0.1 (tets ten times longer than wide), rotated "
                        "and packed";
        const TetMesh slab = cube_lattice(2, 20, 20, Eigen::Vector3d(1, 0.1, 0.1));
        for (int o = 0; o < 12; ++o) {
            const Eigen::Vector3d c(1.2 * (o % 3), 1.2 * ((o / 3) % 2), 1.2 * (o / 6));
            place(s.mesh, slab, rng.rotation(), c);
        }
    } else if (name == "building" || name == "walled" || name == "hall") {
        NamedScene b = building_scene(4, 4); // the same objects in all three (building_scene's own seed)
        if (name == "walled") {
            b.description =
                "the building's objects (208 3^3-cube objects, edge 0.1, in pairs) with cells made from its "
                "walls (box obstacles 0.1 thick with the door gaps): free boxes joined by portals";
            b.cells = std::make_shared<const CellLayout>(cells_from_obstacles(*b.walls));
        }
        if (name == "hall") {
            b.description =
                "the building's objects (208 3^3-cube objects, edge 0.1, in pairs) in one open hall 16 x 16 "
                "x 3: one cell, no portal";
            auto one = std::make_shared<CellLayout>();
            PortalCell c;
            c.name = "hall";
            c.hi[0] = c.hi[1] = 16;
            c.hi[2] = 3;
            one->cells.push_back(c);
            b.cells = one;
            b.walls = nullptr; // an open hall
        }
        b.name = name;
        return b;
    } else {
        std::string list;
        for (const auto& n : partition_scene_names())
            list += (list.empty() ? "" : ", ") + n;
        throw Error("unknown partition scene '" + name + "' (expected one of " + list + ")");
    }
    return s;
}

} // namespace tethash::study
