// Scene::continuous_check: each substep swept by continuous detection (tethash/continuous.hpp), a step taken again
// in more substeps where a far pair met within a substep unwatched. It sees what the check of where vertices end
// cannot: a thin plate passing through a thin plate within a substep and ending beyond it, and an edge passing
// through a face with no vertex inside anything. Runs are the same bit for bit at one and two threads; the scene key
// is read and checked.
#include "sim_support.hpp"
#include "support.hpp"

#include "tethash/sim/quality.hpp"
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

/// A 0.6 × 0.6 plate 0.05 thick thrown down at `speed` onto a static 1 × 1 plate as thin, top at 0.025; no gravity,
/// dt 1/100, no margin or speculative contacts (only what ends inside is pushed), the crossing check on.
Scene plates(double speed, bool continuous)
{
    Scene s;
    ObjectSpec lower = box_object(Eigen::Vector3d(1.0, 1.0, 0.05), {0, 0, 0}, 4);
    lower.is_static = true;
    s.objects.push_back(lower);
    s.objects.push_back(box_object(Eigen::Vector3d(0.6, 0.6, 0.05), {0, 0, 0.4}, 3));
    s.objects[1].velocity = Eigen::Vector3d(0, 0, -speed);
    s.gravity.setZero();
    s.dt = 1.0 / 100;
    s.output.every = 0;
    s.contact.margin = 0;
    s.contact.speculative = false;
    s.crossing_check = true;
    s.continuous_check = continuous;
    return s;
}

/// Lowest vertex of object 1 over `steps` steps.
double lowest(const Scene& s, int steps)
{
    Simulation sim(s);
    const auto [b0, bn] = sim.object_vertices(1);
    double low = INFINITY;
    for (int i = 0; i < steps; ++i) {
        sim.step();
        low = std::min(low, sim.positions().middleRows(b0, bn).col(2).minCoeff());
    }
    return low;
}

/// A bar along y (0.05 thick) thrown down at 10 m/s across a static bar along x as thin, 0.12 above it: after one
/// step of 1/100 it straddles the other, its lower long edges through the other's side faces, and no vertex of
/// either is inside the other (their vertices are at their far ends). No gravity, the crossing check on.
Scene crossed_bars(bool continuous)
{
    Scene s = crossed_bars_scene(0.12);
    s.objects[1].velocity = Eigen::Vector3d(0, 0, -10);
    s.crossing_check = true;
    s.continuous_check = continuous;
    return s;
}

} // namespace

TEST(SimContinuous, ThinPlateThroughAThinPlateWithinASubstep)
{
    // At 15 m/s the plate crosses the whole lower plate (0.05 thick) within a step of 0.15 and ends below it: the
    // crossing check, which looks where vertices end, sees nothing and the plate flies on. The sweep sees its faces
    // meet within the substep and takes the step again in more substeps, until its vertices end inside the lower
    // plate, where they are pushed back: it stays above the lower plate's bottom.
    EXPECT_LT(lowest(plates(15.0, false), 20), -1.0);
    EXPECT_GT(lowest(plates(15.0, true), 20), -0.025);
}

TEST(SimContinuous, EdgeThroughFaceWithNoVertexInside)
{
    // The crossing check sees no vertex inside anything at any step; the sweep sees the edges meet in the first
    // step and takes it again in more substeps.
    for (const bool continuous : {false, true}) {
        Simulation sim(crossed_bars(continuous));
        sim.step();
        EXPECT_EQ(sim.last_stats().contacts, 0) << continuous;
        const auto [b0, bn] = sim.object_vertices(1);
        const double bottom = sim.positions().middleRows(b0, bn).col(2).minCoeff();
        EXPECT_LT(bottom, 0.025) << "the bar ends the step straddling the other";
        EXPECT_GT(bottom, -0.025) << "the bar ends the step straddling the other";
        if (continuous) {
            EXPECT_GT(sim.last_stats().continuous_crossings, 0);
            EXPECT_GT(sim.health().crossing_steps, 0);
        } else {
            EXPECT_EQ(sim.last_stats().crossings, 0);
            EXPECT_EQ(sim.health().crossing_steps, 0);
        }
    }
}

TEST(SimContinuous, RetakesAreCappedAndWhatIsLeftIsReported)
{
    // At 60 m/s the plate crosses the lower plate within a quarter of a step: the sweep takes the step again twice
    // (four substeps), no more, though max_substeps would allow more; the impact left in the last attempt is reported
    // in the step's stats, the run's health and its problems.
    Scene s = plates(60.0, true);
    s.max_substeps = 64;
    Simulation sim(s);
    int capped = 0;
    for (int i = 0; i < 6; ++i) {
        sim.step();
        const StepStats& st = sim.last_stats();
        EXPECT_LE(st.continuous_crossings, 2) << "step " << i + 1;
        if (st.continuous_unresolved > 0) {
            ++capped;
            EXPECT_EQ(st.continuous_crossings, 2) << "step " << i + 1;
            EXPECT_EQ(st.substeps, 4) << "step " << i + 1;
        }
    }
    ASSERT_GT(capped, 0);
    EXPECT_EQ(sim.health().continuous_unresolved_steps, capped);
    const auto problems = sim.health().problems();
    EXPECT_TRUE(std::any_of(problems.begin(), problems.end(), [](const std::string& p) {
        return p.find("continuous check") != std::string::npos;
    })) << problems.size();
}

TEST(SimContinuous, BitIdenticalAtOneAndTwoThreads)
{
    Scene s1 = plates(15.0, true), s2 = s1;
    s1.detect.threads = 1;
    s2.detect.threads = 2;
    Simulation one(s1), two(s2);
    for (int i = 0; i < 6; ++i) {
        one.step();
        two.step();
        ASSERT_EQ(one.last_stats().substeps, two.last_stats().substeps) << "step " << i + 1;
        ASSERT_TRUE((one.positions().array() == two.positions().array()).all()) << "step " << i + 1;
        ASSERT_TRUE((one.velocities().array() == two.velocities().array()).all()) << "step " << i + 1;
    }
    EXPECT_GT(one.health().crossing_steps, 0); // the sweep's retakes were exercised
}

TEST(SimContinuous, SceneKey)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", "continuous_check = true\n[[object]]\ngenerate = { shape = \"box\" }\n");
    EXPECT_TRUE(load_scene((dir / "s.toml").string()).continuous_check);
    write_text(dir / "bad.toml", "continuous_check = \"yes\"\n[[object]]\ngenerate = { shape = \"box\" }\n");
    expect_error([&] { load_scene((dir / "bad.toml").string()); }, {"continuous_check", "bad.toml:1"});
}

TEST(SimContinuous, InsideOtherObjectsCountsVerticesInAnotherBodyOnly)
{
    // Two unit cubes (six tets each, vertices at the corners), the second's centre at (0.8, 0.8, 0.8): its corner
    // (0.3, 0.3, 0.3) is inside the first and the first's corner (0.5, 0.5, 0.5) inside it. The cubes' own vertices
    // lie in their own tets (on them): those are not counted.
    Scene s;
    s.objects.push_back(bar_object({1, 1, 1}, {0, 0, 0}));
    s.objects.push_back(bar_object({1, 1, 1}, {0.8, 0.8, 0.8}));
    s.objects[1].self_collision = true;
    s.output.every = 0;
    Simulation sim(s);
    InsideOtherObjects inside(sim.mesh());
    EXPECT_EQ(inside.count(sim.positions()), 2);
    Positions x = sim.positions();
    const auto [b0, bn] = sim.object_vertices(1);
    x.middleRows(b0, bn).col(2).array() += 1.0; // the second cube above the first, no corner inside
    EXPECT_EQ(inside.count(x), 0);
    x.middleRows(b0, bn).col(2).array() -= 1.6; // centre (0.8, 0.8, 0.2): its corner (0.3, 0.3, -0.3) inside the
    // first, the first's corner (0.5, 0.5, 0.5) inside it
    EXPECT_EQ(inside.count(x), 2);
    x.middleRows(b0, bn).col(0).array() += 0.3; // centre (1.1, 0.8, 0.2): its corners at x = 0.6, none inside
    EXPECT_EQ(inside.count(x), 0);
}
