// Contact before penetration (src/sim/proximity.hpp): margin contacts and speculative contacts. A thin plate
// thrown at another faster than its thickness per step does not tunnel; bodies that start touching are not pushed
// apart by the margin; a margin contact names the nearest face's tet with the closest point's coordinates; the
// scene keys are read and checked (the grid's box filter: test_core_box_grid.cpp).
#include "sim_support.hpp"
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace tethash;
using namespace tethash::sim;
using namespace tethash::test;

namespace {

/// A 0.6 × 0.6 plate `thickness` thick thrown down at `speed` onto a static 1 × 1 plate as thin, top at
/// thickness / 2; no gravity; dt 1/100, so at 8 m/s it moves 0.08 per step, more than the plates' thickness.
Scene plates(double thickness, double speed)
{
    Scene s;
    ObjectSpec lower = box_object(Eigen::Vector3d(1.0, 1.0, thickness), {0, 0, 0}, 4);
    lower.is_static = true;
    s.objects.push_back(lower);
    s.objects.push_back(box_object(Eigen::Vector3d(0.6, 0.6, thickness), {0, 0, 0.4}, 3));
    s.objects[1].velocity = Eigen::Vector3d(0, 0, -speed);
    s.gravity.setZero();
    s.dt = 1.0 / 100;
    s.output.every = 0;
    return s;
}

/// Lowest vertex of the thrown plate over 40 steps.
double lowest(const Scene& s)
{
    Simulation sim(s);
    const auto [b0, bn] = sim.object_vertices(1);
    double low = INFINITY;
    for (int i = 0; i < 40; ++i) {
        sim.step();
        low = std::min(low, sim.positions().middleRows(b0, bn).col(2).minCoeff());
    }
    return low;
}

/// A 0.4 × 0.4 × 0.2 box whose bottom is at `bottom` above a static 2 × 2 plate with its top at z = 0.
Scene box_on_plate(double bottom)
{
    Scene s;
    ObjectSpec plate = box_object(Eigen::Vector3d(2.0, 2.0, 0.2), {0, 0, -0.1}, 3);
    plate.is_static = true;
    s.objects.push_back(plate);
    s.objects.push_back(box_object(Eigen::Vector3d(0.4, 0.4, 0.2), {0, 0, bottom + 0.1}));
    s.dt = 1.0 / 240;
    s.output.every = 0;
    return s;
}

} // namespace

TEST(SimProximity, FastThinPlateDoesNotTunnel)
{
    const double thickness = 0.05, top = thickness / 2;
    for (double speed : {8.0, 15.0}) {
        // Only vertices inside tets pushed, no crossing check: the plate crosses the other between two steps and
        // flies on.
        Scene bare = plates(thickness, speed);
        bare.contact.margin = 0;
        bare.contact.speculative = false;
        bare.crossing_check = false;
        EXPECT_LT(lowest(bare), -1.0) << speed;
        // The crossing check alone holds it at 8 m/s (its vertices end a step inside the lower plate, unseen: the
        // step is taken in more substeps); at 15 m/s they cross the whole plate within a step and end outside it,
        // which a check of where vertices end cannot see.
        bare.crossing_check = true;
        if (speed < 10)
            EXPECT_GT(lowest(bare), top - thickness) << speed;
        else
            EXPECT_LT(lowest(bare), -1.0) << speed;
        // Speculative contacts alone stop it (the gap closing within the step is seen by the iterations) ...
        Scene speculative = plates(thickness, speed);
        speculative.contact.margin = 0;
        EXPECT_GT(lowest(speculative), top - thickness) << speed;
        // ... and so do the defaults (margin and speculative), with no vertex below the lower plate's top by more
        // than a tenth of the thickness.
        EXPECT_GT(lowest(plates(thickness, speed)), top - 0.1 * thickness) << speed;
    }
    // The margin alone (no speculative contacts) holds at 8 m/s, where a vertex ends a step within the margin or
    // inside the plate, and not at 15 m/s: it needs the gap to be found before it is crossed.
    // (Without the crossing check, which would take the steps again where a vertex ends inside the plate.)
    Scene margin_only = plates(thickness, 8.0);
    margin_only.contact.speculative = false;
    margin_only.crossing_check = false;
    EXPECT_GT(lowest(margin_only), top - thickness);
    margin_only = plates(thickness, 15.0);
    margin_only.contact.speculative = false;
    margin_only.crossing_check = false;
    EXPECT_LT(lowest(margin_only), -1.0);
}

TEST(SimProximity, BodiesThatStartTouchingAreNotPushedApart)
{
    // A box resting exactly on a static plate (no gravity): nearer than the margin from the start, so its margin
    // is what it has (nothing): it stays, at rest. Were the full margin applied, the contacts would launch it.
    Scene s = box_on_plate(0.0);
    s.gravity.setZero();
    Simulation sim(s);
    const auto [b0, bn] = sim.object_vertices(1);
    for (int i = 0; i < 120; ++i)
        sim.step();
    EXPECT_LT(sim.velocities().middleRows(b0, bn).rowwise().norm().maxCoeff(), 1e-3);
    EXPECT_NEAR(sim.positions().middleRows(b0, bn).col(2).minCoeff(), 0.0, 1e-3);
}

TEST(SimProximity, MarginContactNamesTheNearestFace)
{
    // A small box falling onto a static plate under gravity comes to rest on margin contacts: each names a tet of
    // the plate, the closest point's coordinates in it (one 0: the point is on a face), a direction away from the
    // plate (up) and a depth below the margin; the box hovers within the margin, above the plate's top.
    Simulation sim(box_on_plate(0.1));
    for (int i = 0; i < 480; ++i)
        sim.step();
    const auto [b0, bn] = sim.object_vertices(1);
    const auto [t0, tn] = sim.object_tets(0);
    double margin = 0;
    int of_box = 0;
    for (const Contact& c : sim.margin_contacts()) {
        if (c.vertex_object != 1) continue; // the plate's vertices near the box's faces push the box too
        ++of_box;
        EXPECT_GE(c.vertex, b0);
        EXPECT_LT(c.vertex, b0 + bn);
        EXPECT_GE(c.tet, t0);
        EXPECT_LT(c.tet, t0 + tn);
        EXPECT_EQ(c.tet_object, 0);
        int zeros = 0;
        double sum = 0;
        for (double b : c.bary) {
            zeros += b == 0 ? 1 : 0;
            sum += b;
        }
        EXPECT_GE(zeros, 1);
        EXPECT_NEAR(sum, 1.0, 1e-9);
        EXPECT_GT(c.direction[2], 0.99);
        const double gap = sim.positions()(c.vertex, 2); // the plate's top is z = 0
        EXPECT_GT(gap, 0.0);
        margin = std::max(margin, gap + c.depth); // depth = margin − distance
    }
    ASSERT_GT(of_box, 0);
    // The margin: a quarter of the box's mean edge, here about 0.03.
    EXPECT_GT(margin, 0.01);
    EXPECT_LT(margin, 0.06);
    EXPECT_LT(sim.positions().middleRows(b0, bn).col(2).minCoeff(), margin);
    EXPECT_TRUE(sim.contacts().empty()); // resting on the margin: nothing inside the plate
}

TEST(SimProximity, SceneKeys)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", "[contact]\nmargin = 0.1\nspeculative = false\n[[object]]\ngenerate = { shape = "
                               "\"box\", resolution = 2 }\n");
    const Scene s = load_scene((dir / "s.toml").string());
    EXPECT_DOUBLE_EQ(s.contact.margin, 0.1);
    EXPECT_FALSE(s.contact.speculative);
    EXPECT_DOUBLE_EQ(Scene{}.contact.margin, 0.25);
    EXPECT_TRUE(Scene{}.contact.speculative);
    write_text(dir / "bad.toml", "[contact]\nmargin = -1\n[[object]]\ngenerate = { shape = \"box\" }\n");
    expect_error([&] { load_scene((dir / "bad.toml").string()); }, {"contact.margin", "bad.toml"});
    write_text(dir / "bad2.toml", "[contact]\nspeculative = 3\n[[object]]\ngenerate = { shape = \"box\" }\n");
    expect_error([&] { load_scene((dir / "bad2.toml").string()); }, {"contact.speculative", "bad2.toml"});
}

TEST(SimProximity, SameMarginContactsAtAnyThreadCount)
{
    // The boundary vertices split over the threads (enough of them: over a thousand): the margin contacts, their
    // order and every field, the same at one and two threads, step after step, as two boxes settle on each other
    // and on a plate.
    auto scene = [](int threads) {
        Scene s = box_on_plate(0.02);
        s.objects.push_back(box_object(Eigen::Vector3d(0.5, 0.5, 0.3), {0.05, 0, 0.45}, 12));
        s.objects[1] = box_object(Eigen::Vector3d(0.4, 0.4, 0.2), {0, 0, 0.12}, 12);
        s.ground.enabled = false;
        s.detect.threads = threads;
        return s;
    };
    Simulation one(scene(1)), two(scene(2));
    size_t most = 0;
    for (int i = 0; i < 60; ++i) {
        one.step();
        two.step();
        const std::vector<Contact>&a = one.margin_contacts(), &b = two.margin_contacts();
        ASSERT_EQ(a.size(), b.size()) << "step " << i + 1;
        most = std::max(most, a.size());
        for (size_t k = 0; k < a.size(); ++k) {
            ASSERT_EQ(a[k].vertex, b[k].vertex) << "step " << i + 1 << " contact " << k;
            ASSERT_EQ(a[k].tet, b[k].tet) << "step " << i + 1 << " contact " << k;
            ASSERT_EQ(a[k].depth, b[k].depth) << "step " << i + 1 << " contact " << k;
            for (int r = 0; r < 3; ++r)
                ASSERT_EQ(a[k].direction[r], b[k].direction[r]) << "step " << i + 1 << " contact " << k;
        }
        ASSERT_TRUE((one.positions().array() == two.positions().array()).all()) << "step " << i + 1;
    }
    EXPECT_GT(most, 100U);
}
