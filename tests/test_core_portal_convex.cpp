// Convex cells and polygon portals (portals.hpp: convex_cell, surface_cell, polygon_portal): a room cut along its
// diagonal into two convex cells joined by a polygon portal, a box cell beside them joined to each by a rectangle
// and a triangle, an empty convex loft and a portal-less cupboard; contacts equal the oracle's for objects straddling
// the diagonal portal, lying exactly on its plane, outside every cell, crossing two cells in one call, at 1 and 2
// threads; cells from closed convex surfaces; the checks refuse what is not a convex cell or a portal on the boundary
// two cells share.
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/portals.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <random>

using namespace tethash;
using namespace tethash::test;
using Vec3 = Eigen::Vector3d;

namespace {

CellPlane plane(double nx, double ny, double nz, double d)
{
    CellPlane p;
    p.n[0] = nx, p.n[1] = ny, p.n[2] = nz;
    p.d = d;
    return p;
}

/// The half-spaces of the box [lo, hi].
std::vector<CellPlane> box_planes(const Vec3& lo, const Vec3& hi)
{
    return {plane(-1, 0, 0, -lo.x()), plane(1, 0, 0, hi.x()),   plane(0, -1, 0, -lo.y()),
            plane(0, 1, 0, hi.y()),   plane(0, 0, -1, -lo.z()), plane(0, 0, 1, hi.z())};
}

std::vector<CellPlane> with(std::vector<CellPlane> planes, const CellPlane& extra)
{
    planes.push_back(extra);
    return planes;
}

/// The room [0, 4] × [0, 2] × [0, 2] cut by x + y = 3 into "west" and "east"; "north" the box [0, 4] × [2, 3] ×
/// [0, 2] beside both; "loft" above, cut by x + z <= 6, empty and without portals; "cupboard" [4, 5] × [0, 1] ×
/// [0, 1] without portals. Portals: a rectangle in the diagonal (polygon), a rectangle between north and east, a
/// triangle between north and west.
std::shared_ptr<CellLayout> diagonal_rooms()
{
    auto l = std::make_shared<CellLayout>();
    const std::vector<CellPlane> room = box_planes({0, 0, 0}, {4, 2, 2});
    l->cells.push_back(convex_cell("west", with(room, plane(1, 1, 0, 3))));
    l->cells.push_back(convex_cell("east", with(room, plane(-1, -1, 0, -3))));
    PortalCell north;
    north.name = "north";
    north.lo[0] = 0, north.lo[1] = 2, north.lo[2] = 0;
    north.hi[0] = 4, north.hi[1] = 3, north.hi[2] = 2;
    l->cells.push_back(north);
    l->cells.push_back(convex_cell("loft", with(box_planes({0, 0, 2}, {4, 3, 3}), plane(1, 0, 1, 6))));
    PortalCell cupboard;
    cupboard.name = "cupboard";
    cupboard.lo[0] = 4, cupboard.lo[1] = 0, cupboard.lo[2] = 0;
    cupboard.hi[0] = 5, cupboard.hi[1] = 1, cupboard.hi[2] = 1;
    l->cells.push_back(cupboard);
    l->portals.push_back(polygon_portal(0, 1, {{2, 1, 0.25}, {1.25, 1.75, 0.25}, {1.25, 1.75, 1.5}, {2, 1, 1.5}}));
    Portal door;
    door.a = 2, door.b = 1;
    door.lo[0] = 1.5, door.lo[1] = 2, door.lo[2] = 0;
    door.hi[0] = 3.5, door.hi[1] = 2, door.hi[2] = 1.5;
    l->portals.push_back(door);
    l->portals.push_back(polygon_portal(2, 0, {{0.2, 2, 0.1}, {0.8, 2, 0.1}, {0.5, 2, 1.0}}));
    check_cell_layout(*l);
    return l;
}

/// Objects across the diagonal (one exactly on it: lattice vertices with x + y = 3), across north's wall and door,
/// into the cupboard, outside every cell, and random ones around (2, 1, 1); in overlapping pairs.
Scene diagonal_scene(std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Scene s = random_scene(seed, 6, 2, 0.2);
    s.positions.rowwise() += Vec3(2, 1, 1).transpose();
    const Vec3 places[] = {{1.4, 1.4, 0.5}, {2.6, 1.8, 0.6}, {0.3, 1.8, 0.3}, {3.8, 0.5, 0.5}, {-0.2, 0.5, 0.5}};
    for (const Vec3& at : places)
        for (int k = 0; k < 2; ++k)
            append_object(s, lattice_object(2, 2, 2, 0.15 + 0.1 * u(rng), at + 0.1 * Vec3(u(rng), u(rng), u(rng))));
    append_object(s, lattice_object(2, 2, 2, 0.25, Vec3(1.5, 1.25, 0.5))); // vertices on x + y = 3
    append_object(s, lattice_object(2, 2, 2, 0.25, Vec3(1.625, 1.375, 0.625)));
    s.objects.resize(static_cast<std::size_t>(s.vertex_object.back()) + 1);
    return s;
}

} // namespace

TEST(CorePortalConvex, DiagonalRoomsEqualTheOracleWhileObjectsMove)
{
    const auto layout = diagonal_rooms();
    EXPECT_EQ(layout->cells[0].hi[0], 3); // west's box: x + y <= 3 with y >= 0
    EXPECT_EQ(layout->cells[1].lo[1], 0);
    for (std::uint32_t seed : {1U, 2U, 3U}) {
        Scene s = diagonal_scene(seed);
        Detector one = portal_detector(s, layout, 1);
        Detector two = portal_detector(s, layout, 2);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(-0.03, 0.03);
        std::int64_t rays = 0, overlaps = 0;
        const Index last = s.vertex_object.back();
        for (int step = 0; step < 8; ++step) {
            const DetectStats st = expect_oracle_at_two_thread_counts(
                one, two, s, "seed " + std::to_string(seed) + " step " + std::to_string(step));
            EXPECT_EQ(st.nodes, 5);
            rays += st.ray_tests;
            overlaps += st.portal_overlaps;
            for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
                const Index o = s.vertex_object[static_cast<std::size_t>(v)];
                for (int k = 0; k < 3; ++k)
                    s.positions(v, k) += u(rng);
                if (o == 6) s.positions(v, 0) += step == 3 ? 1.5 : 0.1; // west, through the diagonal, on east
                if (o == 8) s.positions(v, 1) += 0.15;                  // east into north through the door
                if (o == last) s.positions.row(v) += Vec3(0.2, 0.35, 0).transpose(); // off the diagonal into north
            }
        }
        EXPECT_GT(rays, 0);
        EXPECT_GT(overlaps, 0);
    }
}

TEST(CorePortalConvex, CellsOfClosedConvexSurfaces)
{
    // An octahedron around (2, 1, 1) as one cell, the rest outside; then its bottom apex pushed in: not convex.
    const auto octahedron = [](double bottom) {
        Positions v(6, 3);
        v << 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, 1, 0, 0, bottom;
        v.rowwise() += Vec3(2, 1, 1).transpose();
        Triangles t(8, 3);
        t << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4, 1, 0, 5, 2, 1, 5, 3, 2, 5, 0, 3, 5;
        return std::pair{v, t};
    };
    const auto [v, t] = octahedron(-1);
    auto l = std::make_shared<CellLayout>();
    l->cells.push_back(surface_cell("gem", v, t));
    EXPECT_EQ(l->cells[0].planes.size(), 8U);
    EXPECT_EQ(l->cells[0].lo[2], 0);
    EXPECT_EQ(l->cells[0].hi[0], 3);
    // Turned inwards: the same cell.
    Triangles flipped = t;
    flipped.col(1).swap(flipped.col(2));
    const PortalCell inward = surface_cell("gem", v, flipped);
    for (std::size_t k = 0; k < 8; ++k)
        for (int a = 0; a < 3; ++a)
            EXPECT_EQ(inward.planes[k].n[a], l->cells[0].planes[k].n[a]) << k;
    check_cell_layout(*l);
    const Scene s = diagonal_scene(4);
    const std::vector<Contact> want =
        brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects);
    DetectStats st;
    EXPECT_TRUE(same_contacts(portal_detector(s, l, 2).detect(s.positions, &st), want));
    EXPECT_GT(st.portal_overlaps, 0); // boxes across the gem's faces: in the gem and outside
    const auto [dv, dt] = octahedron(0.5);
    expect_error([&] { (void)surface_cell("dented", dv, dt); }, {"cell 'dented'", "not convex"});
    Triangles open = t.topRows(7);
    expect_error([&] { (void)surface_cell("open", v, open); }, {"cell 'open'"});
}

TEST(CorePortalConvex, ChecksRefuseWhatIsNotAConvexCellOrAPortalOnTheSharedBoundary)
{
    const std::vector<CellPlane> unit = box_planes({0, 0, 0}, {1, 1, 1});
    expect_error([&] { (void)convex_cell("c", {unit[1], unit[3], unit[5]}); }, {"cell 'c'", "at least 4 planes"});
    expect_error([&] { (void)convex_cell("c", {unit[1], unit[3], unit[5], unit[0]}); }, {"cell 'c'", "unbounded"});
    expect_error([&] { (void)convex_cell("c", with(unit, plane(1, 0, 0, -1))); }, {"cell 'c'", "no point in common"});
    expect_error([&] { (void)convex_cell("c", with(unit, plane(0, 0, 0, 1))); }, {"cell 'c'", "zero normal"});
    CellLayout flat;
    flat.cells.push_back(
        convex_cell("flat", with(with(unit, plane(1, 1, 0, 1)), plane(-1, -1, 0, -1)))); // a diagonal sheet
    expect_error([&] { check_cell_layout(flat); }, {"cell 'flat'", "no volume"});

    const CellLayout good = *diagonal_rooms();
    const auto refused = [&](const std::function<void(CellLayout&)>& change, const std::vector<std::string>& parts) {
        CellLayout bad = good;
        change(bad);
        expect_error([&] { check_cell_layout(bad); }, parts);
    };
    // A convex cell overlapping another (a sliver across the diagonal).
    refused(
        [](CellLayout& l) {
            l.cells.push_back(convex_cell("wedge", with(box_planes({0, 0, 0}, {4, 2, 2}), plane(1, 1, 0, 3.5))));
        },
        {"cell 'wedge'", "overlaps cell 'west'"});
    auto polygon = [&](std::vector<std::array<double, 3>> corners) {
        return [corners](CellLayout& l) { l.portals.push_back(polygon_portal(0, 1, corners)); };
    };
    refused(polygon({{2, 1, 0.2}, {1.5, 1.5, 0.2}}), {"'west' - 'east'", "at least 3 corners"});
    refused(polygon({{2, 1, 0.2}, {1.5, 1.5, 0.2}, {1, 2, 0.2}}), {"'west' - 'east'", "no area"});
    refused(polygon({{2, 1, 0.2}, {1.5, 1.5, 0.2}, {1.5, 1.5, 1}, {2.1, 1, 1}}), {"'west' - 'east'", "not planar"});
    refused(polygon({{2, 1, 0.2}, {1, 2, 0.2}, {1.6, 1.4, 0.5}, {1, 2, 1}, {2, 1, 1}}),
            {"'west' - 'east'", "not convex"});
    refused(polygon({{2, 1, 0.2}, {1, 2, 0.2}, {1, 2, 2.5}, {2, 1, 2.5}}),
            {"'west' - 'east'", "not on the shared boundary", "outside cell"});
    refused(polygon({{2, 0.5, 0.2}, {1, 1.5, 0.2}, {1, 1.5, 1}, {2, 0.5, 1}}),
            {"'west' - 'east'", "not on the shared boundary", "not on a face"});
    // A rectangle between north and east off east's side of the wall y = 2 (x < 1 is west's).
    refused([](CellLayout& l) { l.portals[1].lo[0] = 0.5; }, {"'north' - 'east'", "outside cell 'east'"});
}
