// ContactParams::edges: a boundary edge passing through a far boundary face, with no vertex inside anything, is
// pushed out (src/sim/contact_response.cpp, add_edge_contacts). Two bars crossed at rest, each one's long edges
// through the other's side faces and no vertex of either inside the other: with the option the crossing is undone
// within a few steps, without it it stays. The same bit for bit at one and two threads; the scene key is read and
// checked.
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
    Scene s;
    ObjectSpec lower = bar_object({1.0, 0.05, 0.05}, {0, 0, 0});
    lower.is_static = true;
    s.objects.push_back(lower);
    s.objects.push_back(bar_object({0.05, 1.0, 0.05}, {0, 0, 0.03}));
    s.gravity.setZero();
    s.dt = 1.0 / 100;
    s.output.every = 0;
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
