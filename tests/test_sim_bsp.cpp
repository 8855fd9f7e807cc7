// Static polyhedral obstacles kept as BSP trees (collider = "bsp"): a body falls into the concave shipped bowl and
// rests on its pit floor without penetrating it; scene errors.
#include "support.hpp"

#include "tethash/bsp.hpp"
#include "tethash/error.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/sim/simulation.hpp"

#include <filesystem>
#include <string>

using namespace tethash;
using namespace tethash::sim;
using namespace tethash::test;

namespace {

const std::string bowl_path = (std::filesystem::path(TETHASH_SOURCE_DIR) / "meshes/surfaces/bowl.obj").string();

std::string bowl_scene(const std::string& body_at)
{
    return R"(dt = 2e-3
[[object]]
name = "bowl"
mesh = ")" +
           bowl_path +
           R"("
static = true
collider = "bsp"

[[object]]
name = "box"
generate = { shape = "box", resolution = 2, size = 0.3 }
translate = )" +
           body_at + R"(
rotate = [20, 10, 0]
self_collision = false
material = { density = 100, young = 1e4, damping = 0.01 }
)";
}

} // namespace

TEST(SimBsp, BodyFallsIntoTheConcaveBowlAndRestsOnItsFloor)
{
    if (!io::have_assimp()) GTEST_SKIP() << "built without assimp";
    Scene s = parse_scene(bowl_scene("[0.1, -0.05, 0.9]"));
    s.output.every = 0;
    Simulation sim(s);
    ASSERT_EQ(sim.scene().objects.size(), 1u); // the bowl is not a tet object
    const auto [b0, bn] = sim.object_vertices(0);
    const io::SurfaceMesh surface = io::read_surface(bowl_path);
    const Bsp bowl(surface.vertices, surface.triangles);
    double deepest = 0;
    std::int64_t obstacle_contacts = 0;
    for (int i = 0; i < 800; ++i) { // 1.6 s
        sim.step();
        for (Index v = b0; v < b0 + bn; ++v) {
            const BspHit hit = bowl.query(sim.positions().row(v).transpose());
            if (hit.inside) deepest = std::max(deepest, hit.depth);
        }
        for (const Contact& c : sim.contacts()) {
            obstacle_contacts += c.tet < 0;
            if (c.tet < 0) {
                EXPECT_EQ(c.tet_object, 1);
            }
        }
    }
    EXPECT_GT(obstacle_contacts, 0);
    const auto body = sim.positions().middleRows(b0, bn);
    // In the pit (floor at z = 0.2, half width 0.45 there, 0.8 at the rim): on its floor, never through it.
    EXPECT_NEAR(body.col(2).minCoeff(), 0.2, 0.03);
    EXPECT_LT(body.col(0).cwiseAbs().maxCoeff(), 0.8);
    EXPECT_LT(body.col(1).cwiseAbs().maxCoeff(), 0.8);
    EXPECT_LT(deepest, 0.03); // penalty contacts: a few mm at most, never through the floor (0.2 thick)
    EXPECT_LT(sim.velocities().middleRows(b0, bn).rowwise().norm().maxCoeff(), 0.05);
    // The depths reported are the exact distances to the surface.
    sim.refresh_contacts();
    const std::vector<double> exact = sim.exact_depths();
    ASSERT_EQ(exact.size(), sim.contacts().size());
    for (std::size_t q = 0; q < exact.size(); ++q)
        if (sim.contacts()[q].tet < 0) {
            EXPECT_NEAR(sim.contacts()[q].depth, exact[q], 1e-12);
        }
}

TEST(SimBsp, SceneErrors)
{
    // collider = "bsp" needs a static object with a surface file.
    std::string text = bowl_scene("[0, 0, 1]");
    text.replace(text.find("static = true\n"), 14, "");
    EXPECT_THROW(parse_scene(text), Error);
    try {
        parse_scene(text, "s.toml");
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("collider"), std::string::npos) << e.what();
    }
    text = bowl_scene("[0, 0, 1]");
    text.replace(text.find("\"bsp\""), 5, "\"voxels\"");
    try {
        parse_scene(text, "s.toml");
        ADD_FAILURE() << "an unknown collider was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("unknown collider 'voxels'"), std::string::npos) << e.what();
    }
}
