// ContactParams::edges: a boundary edge passing through a far boundary face, with no vertex inside anything, is
// pushed out (src/sim/contact_response.cpp, add_edge_contacts). Two bars crossed at rest, each one's long edges
// through the other's side faces and no vertex of either inside the other: with the option the crossing is undone
// within a few steps, without it it stays. A thin bar pierced straight through a thin slab (no edge of the slab
// through the bar, so no pair): pulled out the short way with the option, left without. The same bit for bit at one
// and two threads; the scene key is read and checked.
#include "sim_support.hpp"
#include "support.hpp"

#include "tethash/edge_contacts.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"

#include <array>
#include <vector>

using namespace tethash;
using namespace tethash::sim;
using namespace tethash::test;

namespace {

/// A bar along y (0.05 thick) at rest across a static bar along x as thin, sunk 0.02 into it: its lower long edges
/// pass through the other's side faces, the other's upper long edges through its side faces, and no vertex of either
/// is inside the other (their vertices are at their far ends). No gravity, dt 1/100.
Scene crossed_bars(bool edges)
{
    Scene s = crossed_bars_scene(0.03);
    s.contact.edges = edges;
    return s;
}

/// Edge-face contacts between the two bars at the simulation's positions (the core's detection, independent of the
/// simulator's use of it).
size_t crossings(const Simulation& sim)
{
    TetMesh m = sim.mesh();
    m.positions = sim.positions();
    return find_edge_face_contacts(m.tets, m.positions, m.vertex_object, m.tet_object).contacts.size();
}

/// A thin bar (0.05 × 0.05 × 1, along z) pierced straight through a static thin slab (1 × 1 × 0.05), off its face
/// diagonals: the bar's edges pass in through the slab's top face and out through its bottom face, no edge of the slab
/// passes through the bar and no vertex of either is inside the other. The bar's lower end is 0.15 below the slab.
Scene pierced_slab(bool edges)
{
    Scene s;
    ObjectSpec slab = bar_object({1.0, 1.0, 0.05}, {0, 0, 0});
    slab.is_static = true;
    s.objects.push_back(slab);
    s.objects.push_back(bar_object({0.05, 0.05, 1.0}, {0.3, -0.2, 0.35}));
    s.gravity.setZero();
    s.dt = 1.0 / 100;
    s.output.every = 0;
    s.contact.edges = edges;
    return s;
}

} // namespace

TEST(SimEdges, CrossedBarsAreUndoneOnlyWithEdgeContacts)
{
    for (const bool edges : {false, true}) {
        Simulation sim(crossed_bars(edges));
        ASSERT_GT(crossings(sim), 0u) << "the bars start crossed";
        int steps = 0;
        for (; steps < 30 && crossings(sim) > 0; ++steps) {
            sim.step();
            EXPECT_EQ(sim.last_stats().contacts, 0) << "no vertex inside anything, step " << steps + 1;
        }
        if (edges) {
            EXPECT_EQ(crossings(sim), 0u) << "the crossing is undone";
            EXPECT_LT(steps, 30);
            const auto [b0, bn] = sim.object_vertices(1);
            EXPECT_GE(sim.positions().middleRows(b0, bn).col(2).minCoeff(), 0.025 - 1e-9)
                << "the upper bar is pushed up out of the lower one";
        } else {
            EXPECT_GT(crossings(sim), 0u) << "nothing pushes the crossing";
            EXPECT_EQ(sim.last_stats().edge_contacts, 0);
        }
    }
}

TEST(SimEdges, SlabPiercedStraightThroughIsUndoneOnlyWithEdgeContacts)
{
    for (const bool edges : {false, true}) {
        Simulation sim(pierced_slab(edges));
        ASSERT_GT(crossings(sim), 0u) << "the bar starts through the slab";
        int steps = 0;
        for (; steps < 100 && crossings(sim) > 0; ++steps) {
            sim.step();
            // Without the edge contacts nothing moves; with them the bar's lower end passes up through the slab.
            if (!edges) {
                EXPECT_EQ(sim.last_stats().contacts, 0) << "no vertex inside anything, step " << steps + 1;
            }
        }
        const auto [b0, bn] = sim.object_vertices(1);
        if (edges) {
            EXPECT_EQ(crossings(sim), 0u) << "the bar is out of the slab";
            EXPECT_LT(steps, 100);
            EXPECT_GE(sim.positions().middleRows(b0, bn).col(2).minCoeff(), 0.025 - 1e-9)
                << "out the short way: the bar's lower end above the slab";
        } else {
            EXPECT_GT(crossings(sim), 0u) << "nothing pushes the bar";
            EXPECT_LT(sim.positions().middleRows(b0, bn).col(2).minCoeff(), -0.1);
        }
    }
}

TEST(SimEdges, BitIdenticalAtOneAndTwoThreads)
{
    Scene s1 = crossed_bars(true), s2 = s1;
    s1.detect.threads = 1;
    s2.detect.threads = 2;
    Simulation one(s1), two(s2);
    bool pushed = false;
    for (int i = 0; i < 10; ++i) {
        one.step();
        two.step();
        pushed = pushed || one.last_stats().edge_contacts > 0;
        ASSERT_EQ(one.last_stats().edge_contacts, two.last_stats().edge_contacts) << "step " << i + 1;
        ASSERT_TRUE((one.positions().array() == two.positions().array()).all()) << "step " << i + 1;
        ASSERT_TRUE((one.velocities().array() == two.velocities().array()).all()) << "step " << i + 1;
    }
    EXPECT_TRUE(pushed); // the edge contacts were exercised
}

TEST(SimEdges, SceneKey)
{
    const auto dir = temp_dir();
    EXPECT_FALSE(Scene{}.contact.edges);
    write_text(dir / "s.toml", "[contact]\nedges = true\n[[object]]\ngenerate = { shape = \"box\" }\n");
    EXPECT_TRUE(load_scene((dir / "s.toml").string()).contact.edges);
    write_text(dir / "bad.toml", "[contact]\nedges = \"yes\"\n[[object]]\ngenerate = { shape = \"box\" }\n");
    expect_error([&] { load_scene((dir / "bad.toml").string()); }, {"contact.edges", "bad.toml:2"});
}
