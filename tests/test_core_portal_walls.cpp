// Cells made from static obstacles (cells_from_obstacles) and the walls of the cells (CellWalls): a building whose
// walls are box obstacles gets its rooms back as free cells joined by portals through the doors only (one component
// with doors, one per room without); detection with those cells equals the oracle's for objects straddling doors and
// walls, exactly on a wall's face, and crossing two cells in one call; the wall query of each vertex's cell equals the
// query of every obstacle, with derived cells, the user's cells, a grid and no cell at all.
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/bsp.hpp"
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/portals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <numeric>
#include <random>

using namespace tethash;
using namespace tethash::test;
using Vec3 = Eigen::Vector3d;

namespace {

/// The closed surface of the box [lo, hi] as an obstacle.
Bsp box_obstacle(const Vec3& lo, const Vec3& hi)
{
    Positions v(8, 3);
    for (int k = 0; k < 8; ++k)
        v.row(k) << (k & 1 ? hi.x() : lo.x()), (k & 2 ? hi.y() : lo.y()), (k & 4 ? hi.z() : lo.z());
    Triangles t(12, 3);
    t << 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5;
    return Bsp(v, t, "box");
}

constexpr double k_room = 2, k_height = 2, k_half = 0.1; // rooms 2 × 2 × 2, walls 0.2 thick
constexpr double k_door_lo = 0.7, k_door_hi = 1.3, k_door_top = 1.2;

/// The walls of nx × ny rooms as box obstacles: the outer walls whole, the inner ones at x = 2i and y = 2j with a
/// door into every room they bound (y or x in 2j + [0.7, 1.3], z in [0, 1.2]) when `doors`.
ObstacleSet building_walls(int nx, int ny, bool doors)
{
    ObstacleSet set;
    const int count[2] = {nx, ny};
    for (int axis = 0; axis < 2; ++axis) {
        const int other = 1 - axis;
        const double span = k_room * count[other] + k_half;
        for (int i = 0; i <= count[axis]; ++i) {
            const double at = k_room * i;
            auto wall = [&](double from, double to, double z0, double z1) {
                Vec3 lo, hi;
                lo[axis] = at - k_half, hi[axis] = at + k_half;
                lo[other] = from, hi[other] = to;
                lo[2] = z0, hi[2] = z1;
                set.add(box_obstacle(lo, hi));
            };
            if (!doors || i == 0 || i == count[axis]) {
                wall(-k_half, span, 0, k_height);
                continue;
            }
            double from = -k_half;
            for (int j = 0; j < count[other]; ++j) {
                wall(from, k_room * j + k_door_lo, 0, k_height);
                wall(k_room * j + k_door_lo, k_room * j + k_door_hi, k_door_top, k_height);
                from = k_room * j + k_door_hi;
            }
            wall(from, span, 0, k_height);
        }
    }
    return set;
}

bool is_free(const PortalCell& c)
{
    return c.name.rfind("free", 0) == 0;
}

/// Connected components of the free cells through the portals.
int free_components(const CellLayout& l)
{
    std::vector<Index> parent(l.cells.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::function<Index(Index)> root = [&](Index c) {
        return parent[static_cast<std::size_t>(c)] == c ? c : root(parent[static_cast<std::size_t>(c)]);
    };
    for (const Portal& p : l.portals)
        parent[static_cast<std::size_t>(root(p.a))] = root(p.b);
    int n = 0;
    for (std::size_t c = 0; c < l.cells.size(); ++c)
        n += is_free(l.cells[c]) && root(static_cast<Index>(c)) == static_cast<Index>(c);
    return n;
}

Vec3 centre(const double lo[3], const double hi[3])
{
    return {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
}

bool in_some_obstacle(const ObstacleSet& set, const Vec3& p)
{
    for (Index o = 0; o < set.size(); ++o)
        if (set[o].contains(p)) return true;
    return false;
}

/// Objects in and around a 3 × 2 building of walls: in the rooms, straddling the doors and the walls, lying on a
/// wall's face (x = 2 - 0.1 exactly), above the building (outside every cell); in overlapping pairs.
Scene objects_in_building(std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Scene> parts;
    const Vec3 places[] = {
        {0.8, 0.8, 0.5}, {1.9, 0.9, 0.3}, // in a room; through the door at x = 2
        {3.0, 1.9, 0.4}, {1.8, 1.6, 0.8}, // through the door at y = 2; through the wall beside a door
        {4.5, 3.0, 1.5}, {5.8, 3.5, 0.2}, // high in a room; into the outer wall
        {2.9, 2.9, 1.9}, {1.0, 3.0, 0.0}, // through the ceiling (outside above); on the floor
    };
    for (const Vec3& at : places)
        for (int k = 0; k < 2; ++k)
            parts.push_back(lattice_object(2, 2, 2, 0.1 + 0.05 * u(rng), at + 0.15 * Vec3(u(rng), u(rng), u(rng))));
    // On the wall face x = 1.9 and the door plane: exact coordinates.
    parts.push_back(lattice_object(2, 2, 2, 0.125, Vec3(1.9, 0.75, 0.25)));
    parts.push_back(lattice_object(2, 2, 2, 0.125, Vec3(1.775, 0.875, 0.25)));
    Scene s = parts.front();
    for (std::size_t k = 1; k < parts.size(); ++k)
        append_object(s, parts[k]);
    s.objects.resize(parts.size());
    return s;
}

::testing::AssertionResult same_obstacle_contacts(const std::vector<ObstacleContact>& got,
                                                  const std::vector<ObstacleContact>& want)
{
    if (got.size() != want.size())
        return ::testing::AssertionFailure() << got.size() << " contacts, want " << want.size();
    for (std::size_t i = 0; i < got.size(); ++i) {
        const ObstacleContact &g = got[i], &w = want[i];
        if (g.vertex != w.vertex || g.obstacle != w.obstacle || g.depth != w.depth ||
            g.direction[0] != w.direction[0] || g.direction[1] != w.direction[1] || g.direction[2] != w.direction[2])
            return ::testing::AssertionFailure()
                   << "contact " << i << ": vertex " << g.vertex << " obstacle " << g.obstacle << ", want vertex "
                   << w.vertex << " obstacle " << w.obstacle;
    }
    return ::testing::AssertionSuccess();
}

} // namespace

TEST(CorePortalWalls, CellsFromWallsAreTheRoomsJoinedByTheDoors)
{
    for (const bool doors : {false, true}) {
        const ObstacleSet walls = building_walls(3, 2, doors);
        const CellLayout l = cells_from_obstacles(walls);
        EXPECT_NO_THROW(check_cell_layout(l));
        // Six rooms apart without doors, one space with them.
        EXPECT_EQ(free_components(l), doors ? 1 : 6) << "doors " << doors;
        // A free cell holds no wall, a solid one is in a wall; every portal's centre is free.
        for (const PortalCell& c : l.cells)
            EXPECT_EQ(in_some_obstacle(walls, centre(c.lo, c.hi)), !is_free(c)) << c.name;
        for (const Portal& p : l.portals) {
            EXPECT_FALSE(in_some_obstacle(walls, centre(p.lo, p.hi)));
            EXPECT_TRUE(is_free(l.cells[static_cast<std::size_t>(p.a)]) &&
                        is_free(l.cells[static_cast<std::size_t>(p.b)]));
        }
        // The cells cover the walls' box: random points lie in some cell.
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> ux(-0.1, 6.1), uy(-0.1, 4.1), uz(0, 2);
        for (int k = 0; k < 2000; ++k) {
            const double p[3] = {ux(rng), uy(rng), uz(rng)};
            bool found = false;
            for (const PortalCell& c : l.cells)
                found = found || (c.lo[0] <= p[0] && p[0] <= c.hi[0] && c.lo[1] <= p[1] && p[1] <= c.hi[1] &&
                                  c.lo[2] <= p[2] && p[2] <= c.hi[2]);
            ASSERT_TRUE(found) << p[0] << " " << p[1] << " " << p[2];
        }
    }
    // The scene's box widens the cells' box: the space around the walls is cells too, and the room, open at the top,
    // joins it.
    const ObstacleSet walls = building_walls(1, 1, false);
    const double lo[3] = {-1, -1, -1}, hi[3] = {3, 3, 4};
    const CellLayout wide = cells_from_obstacles(walls, lo, hi);
    EXPECT_EQ(free_components(wide), 1);
    for (const PortalCell& c : wide.cells)
        for (int a = 0; a < 3; ++a) {
            EXPECT_GE(c.lo[a], lo[a]);
            EXPECT_LE(c.hi[a], hi[a]);
        }
    EXPECT_TRUE(std::any_of(wide.cells.begin(), wide.cells.end(), [&](const PortalCell& c) {
        return c.lo[0] == lo[0] && c.lo[1] == lo[1] && c.lo[2] == lo[2];
    }));
    // Fewer cuts than the walls have coordinates: still a valid layout.
    const CellLayout coarse = cells_from_obstacles(building_walls(3, 2, true), nullptr, nullptr, 3);
    EXPECT_NO_THROW(check_cell_layout(coarse));
    expect_error([] { (void)cells_from_obstacles(ObstacleSet()); }, {"no obstacle"});
    expect_error([&] { (void)cells_from_obstacles(walls, nullptr, nullptr, 1); }, {"at least 2 cuts"});
}

TEST(CorePortalWalls, DetectionWithCellsFromWallsEqualsTheOracle)
{
    const ObstacleSet walls = building_walls(3, 2, true);
    auto layout = std::make_shared<CellLayout>(cells_from_obstacles(walls));
    for (std::uint32_t seed : {1U, 2U}) {
        Scene s = objects_in_building(seed);
        Detector one = portal_detector(s, layout, 1);
        Detector two = portal_detector(s, layout, 2);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(-0.02, 0.02);
        std::int64_t rays = 0;
        for (int step = 0; step < 6; ++step) {
            const DetectStats st = expect_oracle_at_two_thread_counts(
                one, two, s, "seed " + std::to_string(seed) + " step " + std::to_string(step));
            EXPECT_EQ(st.nodes, static_cast<std::int64_t>(layout->cells.size()));
            rays += st.ray_tests;
            for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
                const Index o = s.vertex_object[static_cast<std::size_t>(v)];
                for (int a = 0; a < 3; ++a)
                    s.positions(v, a) += u(rng);
                if (o == 2 || o == 3) s.positions(v, 0) += 0.3; // through the door at x = 2, on into the next room
                if (o == 0) s.positions(v, 0) += step == 2 ? 2.2 : 0.05; // two rooms on in one call
            }
        }
        EXPECT_GT(rays, 0);
    }
}

TEST(CorePortalWalls, WallsOfTheVerticesCellsGiveEveryObstacleContact)
{
    const ObstacleSet walls = building_walls(3, 2, true);
    Scene s = objects_in_building(3);
    // Points exactly on wall faces, edges and corners, in the door gaps, outside the building.
    std::vector<Vec3> extra = {{1.9, 0.5, 0.5}, {2.1, 1.3, 1.2}, {1.9, 0.7, 0}, {2, 1, 1.2}, {-0.1, -0.1, 0},
                               {6.1, 4.1, 2},   {3, 3, 2.5},     {-1, 1, 1},    {2, 2, 1},   {4, 2.1, 2}};
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> ux(-0.5, 6.5), uy(-0.5, 4.5), uz(-0.5, 2.5);
    for (int k = 0; k < 3000; ++k)
        extra.emplace_back(ux(rng), uy(rng), uz(rng));
    Positions p(s.positions.rows() + static_cast<Eigen::Index>(extra.size()), 3);
    p.topRows(s.positions.rows()) = s.positions;
    for (std::size_t k = 0; k < extra.size(); ++k)
        p.row(s.positions.rows() + static_cast<Eigen::Index>(k)) = extra[k].transpose();
    const std::vector<ObstacleContact> want = walls.query(p);
    ASSERT_GT(want.size(), 100U);

    const CellLayout derived = cells_from_obstacles(walls);
    CellLayout rooms; // the user's cells: the rooms' boxes inside the walls
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 2; ++j) {
            PortalCell c;
            c.name = "r" + std::to_string(i) + std::to_string(j);
            c.lo[0] = k_room * i + k_half, c.lo[1] = k_room * j + k_half, c.lo[2] = 0;
            c.hi[0] = k_room * (i + 1) - k_half, c.hi[1] = k_room * (j + 1) - k_half, c.hi[2] = k_height;
            rooms.cells.push_back(c);
        }
    const double glo[3] = {0, 0, 0}, ghi[3] = {5, 3, 1};
    const int gn[3] = {4, 3, 2};
    const CellLayout grid = grid_cell_layout(glo, ghi, gn);
    for (const CellLayout* l : std::vector<const CellLayout*>{&derived, &rooms, &grid}) {
        const CellWalls cw(*l, walls);
        WallStats st;
        EXPECT_TRUE(same_obstacle_contacts(cw.query(p, &st), want)) << l->cells.size() << " cells";
        EXPECT_EQ(st.vertices, p.rows());
        EXPECT_LT(st.tests, st.all) << l->cells.size() << " cells";
    }
    // The objects' vertices, mostly in the rooms, meet a few walls each with the derived cells.
    {
        const CellWalls cw(derived, walls);
        WallStats st;
        EXPECT_TRUE(same_obstacle_contacts(cw.query(s.positions, &st), walls.query(s.positions)));
        EXPECT_LT(st.tests, st.all / 2);
    }
    // No cell: every vertex outside, against every obstacle.
    const CellWalls none(CellLayout(), walls);
    WallStats st;
    EXPECT_TRUE(same_obstacle_contacts(none.query(p, &st), want));
    EXPECT_EQ(st.tests, st.all);
    EXPECT_EQ(st.outside, p.rows());
    // A derived free cell's walls: the walls touching it, not the far ones.
    const CellWalls cw(derived, walls);
    for (std::size_t c = 0; c < derived.cells.size(); ++c)
        EXPECT_LT(cw.walls(static_cast<Index>(c)).size(), static_cast<std::size_t>(walls.size()));
}
