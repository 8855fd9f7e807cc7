// The cells-and-portals broad phase (Method::portals, portals.hpp) with cell layouts given by the user: contacts equal
// the oracle's for objects straddling portals and walls, lying exactly on a portal's plane, outside every cell, in a
// portal-less cell, moving across two cells in one call; the same at 1 and 2 threads; the layout checks.
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/oracle.hpp"
#include "tethash/portals.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>

using namespace tethash;
using namespace tethash::test;

namespace {

std::vector<Contact> run_oracle(const Scene& s)
{
    return brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object, s.objects);
}

PortalCell cell(const std::string& name, double x0, double y0, double z0, double x1, double y1, double z1)
{
    PortalCell c;
    c.name = name;
    c.lo[0] = x0, c.lo[1] = y0, c.lo[2] = z0;
    c.hi[0] = x1, c.hi[1] = y1, c.hi[2] = z1;
    return c;
}

Portal portal(Index a, Index b, double x0, double y0, double z0, double x1, double y1, double z1)
{
    Portal p;
    p.a = a, p.b = b;
    p.lo[0] = x0, p.lo[1] = y0, p.lo[2] = z0;
    p.hi[0] = x1, p.hi[1] = y1, p.hi[2] = z1;
    return p;
}

/// Three rooms of 2 × 2 × 2 in a row along x joined by doors (y 0.5..1.5, z 0..1.5) on x = 2 and x = 4; an empty
/// room above the first (door in its floor); a closet beside the third without any portal; an empty porch behind the
/// third. The scene's objects may
/// also lie outside every room (x < 0 or y > 2).
std::shared_ptr<CellLayout> building()
{
    auto l = std::make_shared<CellLayout>();
    l->cells = {cell("hall", 0, 0, 0, 2, 2, 2),  cell("kitchen", 2, 0, 0, 4, 2, 2), cell("study", 4, 0, 0, 6, 2, 2),
                cell("attic", 0, 0, 2, 2, 2, 4), cell("closet", 4, -1, 0, 6, 0, 2), cell("porch", 6, 0, 0, 8, 2, 2)};
    l->portals = {portal(0, 1, 2, 0.5, 0, 2, 1.5, 1.5), portal(1, 2, 4, 0.5, 0, 4, 1.5, 1.5),
                  portal(3, 0, 0.5, 0.5, 2, 1.5, 1.5, 2), portal(2, 5, 6, 0.5, 0, 6, 1.5, 1.5)};
    check_cell_layout(*l);
    return l;
}

/// A lattice object of n³ cubes of edge h at `origin`, turned by `angle` about a tilted axis (0: axis-aligned, with
/// exactly representable coordinates when origin and h are).
Scene object_at(int n, double h, const Eigen::Vector3d& origin, double angle)
{
    Scene o = lattice_object(n, n, n, h, Eigen::Vector3d::Zero());
    const Eigen::Matrix3d rot = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    for (Eigen::Index v = 0; v < o.positions.rows(); ++v)
        o.positions.row(v) = (rot * o.positions.row(v).transpose() + origin).transpose();
    return o;
}

/// Objects spread over the building: straddling the doors, the walls and the attic's floor, exactly on the door
/// plane x = 2, in the closet, outside every room; pairs of objects overlap so that there are contacts.
Scene building_scene(std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Scene s;
    s.positions.resize(0, 3);
    s.tets.resize(0, 4);
    const Eigen::Vector3d places[] = {
        {1.7, 0.8, 0.5},  // through the first door
        {3.8, 0.7, 0.3},  // through the second door
        {1.8, 1.7, 0.5},  // through the wall beside the first door
        {0.7, 0.8, 1.8},  // through the attic's floor
        {4.5, -0.6, 0.5}, // in the closet
        {4.8, -0.2, 1.0}, // closet and study, through their wall (no portal)
        {-0.3, 0.5, 0.5}, // half outside the hall
        {2.5, 2.6, 0.5},  // outside every room
    };
    for (const Eigen::Vector3d& at : places)
        for (int k = 0; k < 2; ++k) {
            const Eigen::Vector3d jitter(0.2 * u(rng), 0.2 * u(rng), 0.2 * u(rng));
            append_object(s, object_at(2, 0.2 + 0.1 * u(rng), at + jitter, 6 * u(rng)));
        }
    // Exactly on the door plane x = 2 and on the kitchen's floor z = 0: vertices of one lattice on the other's faces.
    append_object(s, object_at(2, 0.25, {2.0, 0.75, 0.0}, 0));
    append_object(s, object_at(2, 0.25, {1.75, 0.75, 0.0}, 0));
    append_object(s, object_at(2, 0.25, {2.0, 1.0, 0.25}, 0));
    s.objects.resize(static_cast<std::size_t>(s.vertex_object.back()) + 1);
    return s;
}

} // namespace

TEST(CorePortals, BuildingEqualsTheOracleAtOneAndTwoThreads)
{
    for (std::uint32_t seed : {1U, 2U, 3U}) {
        const Scene s = building_scene(seed);
        const std::vector<Contact> want = run_oracle(s);
        ASSERT_GT(want.size(), 20U);
        Detector one = portal_detector(s, building(), 1);
        Detector two = portal_detector(s, building(), 2);
        DetectStats st;
        const std::vector<Contact> a = one.detect(s.positions, &st);
        EXPECT_TRUE(same_contacts(a, want)) << "seed " << seed;
        EXPECT_TRUE(identical(a, two.detect(s.positions))) << "seed " << seed;
        EXPECT_EQ(st.nodes, 6);
        EXPECT_GT(st.portal_overlaps, 0); // boxes across the doors, walls and the outside
        EXPECT_EQ(st.ray_tests, 0);       // nothing moved yet
    }
}

TEST(CorePortals, ObjectsMovingThroughDoorsAndWallsAndTwoCellsInOneCall)
{
    Scene s = building_scene(4);
    Detector one = portal_detector(s, building(), 1);
    Detector two = portal_detector(s, building(), 2);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-0.03, 0.03);
    std::int64_t rays = 0;
    for (int step = 0; step < 10; ++step) {
        for (Eigen::Index v = 0; v < s.positions.rows(); ++v) {
            const Index o = s.vertex_object[static_cast<std::size_t>(v)];
            for (int a = 0; a < 3; ++a)
                s.positions(v, a) += u(rng);
            if (o == 0) s.positions(v, 0) += step == 3 ? 2.0 : 0.1; // from the hall through the kitchen at once
            if (o == 2) s.positions(v, 1) -= 0.15;                  // back and forth through the wall
            if (o == 6) s.positions(v, 2) += 0.2;                   // up into the attic (door or floor)
            if (o == 14) s.positions(v, 1) -= 0.3;                  // from outside into the kitchen
        }
        DetectStats st;
        const std::vector<Contact>& a = one.detect(s.positions, &st);
        EXPECT_TRUE(same_contacts(a, run_oracle(s))) << "step " << step;
        EXPECT_TRUE(identical(a, two.detect(s.positions))) << "step " << step;
        rays += st.ray_tests;
    }
    EXPECT_GT(rays, 0);
}

TEST(CorePortals, EmptyLayoutOneCellAndNoLayoutAreExact)
{
    const Scene s = random_scene(12, 6, 3, 0.3);
    const std::vector<Contact> want = run_oracle(s);
    ASSERT_FALSE(want.empty());
    // No cells at all: every box in the outside cell.
    auto none = std::make_shared<CellLayout>();
    EXPECT_TRUE(same_contacts(portal_detector(s, none, 2).detect(s.positions), want));
    // One cell covering half of the scene, the rest outside.
    auto half = std::make_shared<CellLayout>();
    half->cells = {cell("half", -5, -5, -5, 0.1, 5, 5)};
    EXPECT_TRUE(same_contacts(portal_detector(s, half, 1).detect(s.positions), want));
    // A grid of cells over part of the scene, every shared face a portal.
    const double lo[3] = {-0.7, -0.9, -0.4}, hi[3] = {0.9, 0.6, 1.1};
    const int n[3] = {3, 2, 4};
    auto grid = std::make_shared<CellLayout>(grid_cell_layout(lo, hi, n));
    EXPECT_EQ(grid->portals.size(), 2U * 2 * 4 + 3 * 1 * 4 + 3 * 2 * 3);
    DetectStats st;
    EXPECT_TRUE(same_contacts(portal_detector(s, grid, 2).detect(s.positions, &st), want));
    EXPECT_EQ(st.nodes, 24);
    // No layout: cells of the method's own making.
    EXPECT_TRUE(same_contacts(portal_detector(s, nullptr, 1).detect(s.positions), want));
}

TEST(CorePortals, ExtremeCellSizesAreExact)
{
    // Cells of every scale at once: half of space up to 1e308 (its extent overflows), a sliver 1e-310 thick (its
    // inverse overflows) and a cell beside it with the scene inside; the locator and the slabs must stay exact.
    const Scene s = random_scene(21, 5, 3, 0.3);
    const std::vector<Contact> want = run_oracle(s);
    auto l = std::make_shared<CellLayout>();
    l->cells = {cell("west", -1e308, -1e308, -1e308, 0, 1e308, 1e308), cell("sliver", 0, -1, -1, 1e-310, 1, 1),
                cell("east", 1e-310, -1, -1, 1, 1, 1)};
    l->portals = {portal(0, 1, 0, -1, -1, 0, 1, 1), portal(1, 2, 1e-310, -0.5, -0.5, 1e-310, 0.5, 0.5)};
    check_cell_layout(*l);
    for (int threads : {1, 2}) {
        Detector det = portal_detector(s, l, threads);
        EXPECT_TRUE(same_contacts(det.detect(s.positions), want)) << "threads " << threads;
        Scene moved = s; // everything moves east by 0.3: through the sliver's portals, or past them
        moved.positions.col(0).array() += 0.3;
        EXPECT_TRUE(same_contacts(det.detect(moved.positions), run_oracle(moved))) << "threads " << threads;
    }
}

TEST(CorePortals, LayoutChecksNameTheCellsAndPortals)
{
    auto l = *building();
    auto refused = [](CellLayout bad, const std::vector<std::string>& parts) {
        expect_error([&] { check_cell_layout(bad); }, parts);
        DetectParams p;
        p.method = Method::portals;
        p.partition.cells = std::make_shared<CellLayout>(std::move(bad));
        expect_error([&] { Detector det(p); }, parts);
    };
    CellLayout bad = l;
    bad.cells.push_back(cell("pantry", 1, 1, 1, 3, 3, 3));
    refused(bad, {"cell 'pantry'", "overlaps cell 'hall'"});
    bad = l;
    bad.cells[1].hi[2] = -1;
    refused(bad, {"cell 'kitchen'", "inverted"});
    bad = l;
    bad.cells.push_back(cell("hall", 10, 0, 0, 11, 1, 1));
    refused(bad, {"cell 'hall'", "used twice"});
    bad = l;
    bad.portals.push_back(portal(0, 9, 2, 0.5, 0, 2, 1.5, 1.5));
    refused(bad, {"unknown cell"});
    bad = l;
    bad.portals.push_back(portal(0, 2, 2, 0.5, 0, 2, 1.5, 1.5));
    refused(bad, {"'hall' - 'study'", "share no face"});
    bad = l;
    bad.portals[0].lo[0] = 1.9;
    refused(bad, {"'hall' - 'kitchen'", "not on the shared face"});
    bad = l;
    bad.portals[0].hi[1] = 2.5;
    refused(bad, {"'hall' - 'kitchen'", "leaves the shared face"});
    bad = l;
    bad.portals[0].a = 1;
    refused(bad, {"two different cells"});
}
