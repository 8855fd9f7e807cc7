// Static obstacles given as closed surfaces, friction, per-pair contact stiffness, and the per-substep
// blow-up test of the simulator.
#include "sim_support.hpp"
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/sim/simulation.hpp"

#include <cmath>
#include <string>

using namespace tethash;
using namespace tethash::sim;
using namespace tethash::test;

namespace {

/// Horizontal speed of object k (mean over its vertices).
double horizontal_speed(const Simulation& sim, int k)
{
    const auto [first, count] = sim.object_vertices(k);
    const Eigen::Vector3d v = sim.velocities().middleRows(first, count).colwise().mean().transpose();
    return std::hypot(v.x(), v.y());
}

} // namespace

TEST(SimObstacle, BodyComesToRestOnAClosedSurfaceObstacle)
{
    if (!io::have_assimp()) GTEST_SKIP() << "built without assimp";
    const auto dir = temp_dir();
    // The obstacle: the boundary of a generated slab, written as OBJ, read back through assimp and
    // tetrahedralized on load.
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = 3;
    g.size = Eigen::Vector3d(1.2, 1.2, 0.4);
    const std::string obj = (dir / "slab.obj").string();
    io::write_surface(obj, meshing::boundary_surface(meshing::generate(g)));

    Scene s;
    ObjectSpec slab;
    slab.name = "slab";
    slab.mesh = obj;
    slab.surface_resolution = 6;
    slab.is_static = true;
    s.objects.push_back(slab);
    s.objects.push_back(box_object(Eigen::Vector3d::Constant(0.3), {0.1, -0.1, 0.6}));
    s.dt = 2e-3;
    s.output.every = 0;
    Simulation sim(s);
    const auto [o0, on] = sim.object_vertices(0);
    ASSERT_GT(on, 0);
    ASSERT_GT(sim.object_tets(0).second, 0); // tetrahedralized
    const double top = sim.positions().middleRows(o0, on).col(2).maxCoeff();
    EXPECT_NEAR(top, 0.2, 0.05); // the slab spans z in [-0.2, 0.2]
    const auto [b0, bn] = sim.object_vertices(1);
    double lowest = 1e9;
    for (int i = 0; i < 400; ++i) {
        sim.step();
        lowest = std::min(lowest, sim.positions().middleRows(b0, bn).col(2).minCoeff());
    }
    const auto body = sim.positions().middleRows(b0, bn);
    // Never fell through, and rests on top: bottom at the top face, centre half the box above it, still.
    EXPECT_GT(lowest, top - 0.1);
    EXPECT_NEAR(body.col(2).minCoeff(), top, 0.05);
    EXPECT_NEAR(body.col(2).mean(), top + 0.15, 0.05);
    EXPECT_LT(sim.velocities().middleRows(b0, bn).rowwise().norm().maxCoeff(), 0.05);
}

TEST(SimFriction, GroundFrictionDeceleratesAndStopsASlidingBox)
{
    auto slide = [](double friction) {
        Scene s;
        s.objects.push_back(box_object(Eigen::Vector3d(0.4, 0.4, 0.2), {0, 0, 0.1}));
        s.objects[0].velocity = Eigen::Vector3d(2.0, 0, 0);
        s.ground.enabled = true;
        s.ground.friction = friction;
        s.dt = 2e-3;
        s.output.every = 0;
        Simulation sim(s);
        for (int i = 0; i < 200; ++i)
            sim.step(); // 0.4 s
        EXPECT_TRUE(sim.positions().allFinite());
        return horizontal_speed(sim, 0);
    };
    // μ = 1 stays below the tipping threshold of this 0.4 × 0.2 box (μ = width / height = 2).
    const double free = slide(0.0), some = slide(0.3), high = slide(1.0);
    EXPECT_GT(free, 1.8);                           // without friction it keeps sliding
    EXPECT_NEAR(some, 2.0 - 0.3 * 9.81 * 0.4, 0.1); // Coulomb: μ g t ≈ 1.18 less after 0.4 s
    EXPECT_LT(high, 0.03);                          // μ = 1 stops it within ~0.2 s
}

TEST(SimFriction, ASceneInOtherLengthUnitsMovesTheSame)
{
    // On a slope less steep than their friction angle, a box on the ground and a box on a static plate are held by
    // friction, creeping at its smoothing speed. The same scene in a unit of length 1024 times smaller (about
    // millimetres: lengths and gravity × 1024, young / 1024, density / 1024³) must move the same, 1024 times larger:
    // nothing in the simulator may depend on the unit of length (a smoothing speed written as 1e-3 m/s differs by
    // 1.5e-4 m here). A power of two keeps every scaled input exact, so the runs agree to rounding; with 1000 the
    // rounding differences steer the sweeps' convergence tests apart by tens of micrometres.
    const double tilt = 0.2;
    auto run = [&](double unit) {
        Scene s;
        auto scaled = [&](const Eigen::Vector3d& size, const Eigen::Vector3d& at) {
            ObjectSpec o = box_object(size * unit, at * unit);
            o.material.young /= unit;
            o.material.density /= unit * unit * unit;
            return o;
        };
        ObjectSpec plate = scaled({0.8, 0.8, 0.2}, {2, 0, 0.1});
        plate.is_static = true;
        s.objects = {scaled({0.4, 0.4, 0.2}, {0, 0, 0.1}), plate, scaled({0.4, 0.4, 0.2}, {2, 0, 0.3})};
        s.gravity = 9.81 * unit * Eigen::Vector3d(std::sin(tilt), 0, -std::cos(tilt));
        s.ground.enabled = true;
        s.ground.friction = 0.5;
        s.contact.friction = 0.5;
        s.dt = 1.0 / 240;
        s.output.every = 0;
        Simulation sim(s);
        for (int i = 0; i < 60; ++i)
            sim.step(); // 0.25 s
        EXPECT_TRUE(sim.positions().allFinite());
        return Eigen::MatrixXd(sim.positions() / unit);
    };
    const Eigen::MatrixXd metres = run(1.0), small_units = run(1024.0);
    ASSERT_EQ(metres.rows(), small_units.rows());
    EXPECT_LT((metres - small_units).cwiseAbs().maxCoeff(), 1e-7) << "largest difference, in m";
}

TEST(SimFriction, ContactFrictionOnAStaticObstacle)
{
    auto slide = [](double friction) {
        Scene s;
        ObjectSpec plate = box_object(Eigen::Vector3d(3.0, 1.0, 0.2), {0.5, 0, -0.1}, 3);
        plate.is_static = true;
        s.objects.push_back(plate);
        s.objects.push_back(box_object(Eigen::Vector3d(0.4, 0.4, 0.2), {-0.5, 0, 0.1}));
        s.objects[1].velocity = Eigen::Vector3d(2.0, 0, 0);
        s.contact.friction = friction;
        s.dt = 2e-3;
        s.output.every = 0;
        Simulation sim(s);
        for (int i = 0; i < 200; ++i)
            sim.step();
        EXPECT_TRUE(sim.positions().allFinite());
        const auto [b0, bn] = sim.object_vertices(1);
        EXPECT_GT(sim.positions().middleRows(b0, bn).col(2).minCoeff(), -0.05); // stayed on the plate
        return horizontal_speed(sim, 1);
    };
    const double free = slide(0.0), some = slide(0.3), high = slide(2.0);
    EXPECT_GT(free, 1.7);
    EXPECT_LT(some, free - 0.6);
    EXPECT_LT(high, 0.05);
}

TEST(SimContactStiffness, FollowsTheSofterMaterialAndTheEffectiveMass)
{
    Scene s;
    ObjectSpec cushion = box_object(Eigen::Vector3d(1.0, 1.0, 0.3), {0, 0, 0.15}, 3);
    cushion.material.young = 1e6;
    ObjectSpec steel = box_object(Eigen::Vector3d::Constant(0.4), {0, 0, 0.5}, 2);
    steel.material.young = 1e9;
    steel.material.density = 1e5;
    ObjectSpec table = box_object(Eigen::Vector3d(2.0, 2.0, 0.2), {0, 0, -0.1}, 2);
    table.is_static = true;
    s.objects = {cushion, steel, table};
    s.dt = 5e-3;
    s.integrator = Integrator::implicit_euler;
    s.output.every = 0;
    Simulation sim(s);
    // ω² = young / (density · mean edge²) per object.
    const auto& w2 = sim.model().object_frequency_sq;
    ASSERT_EQ(w2.size(), 3U);
    for (int o = 0; o < 2; ++o) {
        const sim::Material& mat = s.objects[static_cast<size_t>(o)].material;
        const double lbar = sim.model().object_mean_edge[static_cast<size_t>(o)];
        EXPECT_NEAR(w2[static_cast<size_t>(o)], mat.young / (mat.density * lbar * lbar), 1e-9 * w2[0]);
    }
    EXPECT_EQ(w2[2], 0.0); // static
    ASSERT_GT(w2[1], 2 * w2[0]);
    // Steel on cushion: the softer (the cushion's) frequency, whichever side is the vertex; proportional to the
    // effective mass.
    const double m = 0.01;
    EXPECT_DOUBLE_EQ(sim.contact_stiffness(0, 1, m), 50 * w2[0] * m);
    EXPECT_DOUBLE_EQ(sim.contact_stiffness(1, 0, m), sim.contact_stiffness(0, 1, m));
    EXPECT_DOUBLE_EQ(sim.contact_stiffness(0, 1, 2 * m), 2 * sim.contact_stiffness(0, 1, m));
    EXPECT_DOUBLE_EQ(sim.contact_stiffness(1, 2, m), 50 * w2[1] * m); // static partner: the steel's own
    EXPECT_DOUBLE_EQ(sim.contact_stiffness(1, 1, m), 50 * w2[1] * m);
    EXPECT_THROW(sim.contact_stiffness(0, 3, m), Error);
    EXPECT_THROW(sim.contact_stiffness(0, 1, -1.0), Error);

    // The steel block settles on the cushion (implicit Euler, automatic stiffness): finite, no energy
    // gain, shallow penetration.
    const double e0 = sim.energy().total();
    double emax = e0;
    for (int i = 0; i < 80; ++i) {
        sim.step();
        emax = std::max(emax, sim.energy().total());
    }
    EXPECT_TRUE(sim.positions().allFinite());
    EXPECT_LE(emax, e0 + 1e-6 * std::abs(e0));
    EXPECT_LT(sim.max_penetration(), 0.05);

    s.contact.stiffness = 123.0; // given: used for every pair
    Simulation fixed(s);
    EXPECT_DOUBLE_EQ(fixed.contact_stiffness(0, 1, m), 123.0);
    EXPECT_DOUBLE_EQ(fixed.contact_stiffness(1, 1, 5 * m), 123.0);
}

TEST(SimBlowUp, CaughtWithinTheStepBeforeDetectionFails)
{
    // Symplectic Euler far above its limit with substeps: the state diverges within one step. The run must
    // stop with a RunFailure naming the step and substep (not a detector Error about the grid), and keep
    // the last good state.
    Scene s;
    s.objects.push_back(box_object(Eigen::Vector3d::Constant(0.5), {0, 0, 0.3}));
    s.objects.push_back(box_object(Eigen::Vector3d::Constant(0.4), {0.1, 0, 0.7}));
    s.ground.enabled = true;
    s.integrator = Integrator::symplectic_euler;
    s.dt = 5e-2;
    s.substeps = 5;
    s.output.every = 0;
    Simulation sim(s);
    ASSERT_FALSE(sim.warnings().empty());
    Positions good;
    std::int64_t last_good = 0;
    std::string message;
    try {
        for (int i = 0; i < 200; ++i) {
            good = sim.positions();
            last_good = sim.step_index();
            sim.step();
        }
    } catch (const RunFailure& e) {
        message = e.what();
    } catch (const Error& e) {
        FAIL() << "a blow-up surfaced as a bad-input Error: " << e.what();
    }
    ASSERT_FALSE(message.empty()) << "no blow-up detected";
    EXPECT_NE(message.find("step " + std::to_string(last_good + 1) + ", substep "), std::string::npos) << message;
    EXPECT_NE(message.find("likely cause"), std::string::npos) << message;
    EXPECT_EQ(message.find("grid"), std::string::npos) << message;
    EXPECT_EQ(sim.step_index(), last_good);
    EXPECT_TRUE(sim.positions().allFinite());
    EXPECT_TRUE((sim.positions().array() == good.array()).all());
}
