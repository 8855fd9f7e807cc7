// Scene::crossing_check: a step in which a vertex entered a far part within one substep, unseen by the contacts of
// the substep's start, is taken again in more substeps. A shared mesh whose thin limbs cross each other within a
// step at 1/60 has far self-penetrations at some frame without it and none with it; its runs are the same bit for
// bit at one and two threads; the scene key is read and checked. Skips cleanly where ../shared/meshes is absent.
#include "support.hpp"

#include "tethash/io/mesh_io.hpp"
#include "tethash/sim/quality.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

using namespace tethash;
using namespace tethash::sim;

namespace {

/// `mesh` scaled so that its longest extent is `size`, centred over the origin, its lowest point 0.2 × size above
/// the ground (the simulator benchmark's drop), at dt 1/60.
Scene drop(const TetMesh& mesh, double size, bool crossing_check)
{
    const auto [lo, hi] = bounding_box(mesh.positions);
    ObjectSpec o;
    const double s = size / (hi - lo).maxCoeff();
    o.scale = Eigen::Vector3d::Constant(s);
    o.translate = Eigen::Vector3d(-s * 0.5 * (lo.x() + hi.x()), -s * 0.5 * (lo.y() + hi.y()), 0.2 * size - s * lo.z());
    o.data = mesh;
    o.material.density = 1000;
    o.material.young = 1e5;
    Scene scene;
    scene.objects.push_back(o);
    scene.ground.enabled = true;
    scene.dt = 1.0 / 60;
    scene.output.every = 0;
    scene.crossing_check = crossing_check;
    return scene;
}

/// The raptor of the shared meshes, or nullopt where they are absent.
std::optional<TetMesh> raptor()
{
    const auto path = test::shared_mesh("raptorTetra_8418.vtu");
    if (!path) return std::nullopt;
    return io::read_mesh(path->string());
}

/// The most far self-penetrations at the end of any of `steps` steps (every step is a frame at 1/60), and the
/// steps taken again for crossings.
std::pair<std::int64_t, std::int64_t> worst_far(const Scene& scene, int steps)
{
    Simulation sim(scene);
    FarSelfPenetrations far(sim.mesh(), sim.positions());
    std::int64_t worst = 0;
    for (int i = 0; i < steps; ++i) {
        sim.step();
        worst = std::max(worst, far.count(sim.positions()));
    }
    return {worst, sim.health().crossing_steps};
}

} // namespace

TEST(SimCrossings, ThinLimbsDoNotCrossUnseen)
{
    const std::optional<TetMesh> mesh = raptor();
    if (!mesh) GTEST_SKIP() << "../shared/meshes absent";
    // The 15 cm raptor at 1/60: at its 7th step (landing) a limb's vertices end inside a far part of the body
    // (17 of them); with the check that step is taken in 2 substeps, the next in 4, and none is inside.
    const auto [without, no_retakes] = worst_far(drop(*mesh, 0.15, false), 9);
    EXPECT_GT(without, 0);
    EXPECT_EQ(no_retakes, 0);
    const auto [with, retakes] = worst_far(drop(*mesh, 0.15, true), 9);
    EXPECT_EQ(with, 0);
    EXPECT_GT(retakes, 0);
}

TEST(SimCrossings, BitIdenticalAtOneAndTwoThreads)
{
    const std::optional<TetMesh> mesh = raptor();
    if (!mesh) GTEST_SKIP() << "../shared/meshes absent";
    Scene s1 = drop(*mesh, 0.15, true), s2 = s1;
    s1.detect.threads = 1;
    s2.detect.threads = 2;
    Simulation one(s1), two(s2);
    for (int i = 0; i < 8; ++i) {
        one.step();
        two.step();
        ASSERT_EQ(one.last_stats().substeps, two.last_stats().substeps) << "step " << i + 1;
        ASSERT_TRUE((one.positions().array() == two.positions().array()).all()) << "step " << i + 1;
        ASSERT_TRUE((one.velocities().array() == two.velocities().array()).all()) << "step " << i + 1;
    }
    EXPECT_GT(one.health().crossing_steps, 0); // the retakes were exercised
}

TEST(SimCrossings, SceneKey)
{
    const auto dir = test::temp_dir();
    test::write_text(dir / "s.toml", "crossing_check = true\n[[object]]\ngenerate = { shape = \"box\" }\n");
    EXPECT_TRUE(load_scene((dir / "s.toml").string()).crossing_check);
    test::write_text(dir / "bad.toml", "crossing_check = \"yes\"\n[[object]]\ngenerate = { shape = \"box\" }\n");
    test::expect_error([&] { load_scene((dir / "bad.toml").string()); }, {"crossing_check", "bad.toml:1"});
}
