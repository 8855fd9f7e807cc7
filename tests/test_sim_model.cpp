// The mass-spring model and the integrators without contacts: forces against energies, masses, the
// matrix-free operator against the assembled matrix, energy behaviour, stability limit and blow-up.
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/sim/simulation.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <random>

using namespace tethash;
using tethash::test::expect_error;
using namespace tethash::sim;

namespace {

TetMesh box_mesh(int res = 2, double size = 1.0)
{
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = res;
    g.size = Eigen::Vector3d::Constant(size);
    return meshing::generate(g);
}

/// `x` with every coordinate moved by a uniform random amount in [−amplitude, amplitude] (a fixed `seed`).
Positions perturbed(Positions x, unsigned seed, double amplitude)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-amplitude, amplitude);
    for (Index i = 0; i < x.rows(); ++i)
        for (int c = 0; c < 3; ++c)
            x(i, c) += u(rng);
    return x;
}

/// One free box, no gravity, no ground, no collisions: only the elastic model acts.
Scene free_box(Integrator integ, double dt, double damping = 0.0, double perturb = 0.05)
{
    Scene s;
    ObjectSpec o;
    TetMesh m = box_mesh(2);
    m.rest_positions = m.positions;
    m.positions = perturbed(m.positions, 7, perturb);
    o.data = m;
    o.self_collision = false;
    o.material.young = 1e4;
    o.material.density = 100;
    o.material.damping = damping;
    s.objects.push_back(o);
    s.gravity.setZero();
    s.dt = dt;
    s.integrator = integ;
    s.output.every = 0;
    return s;
}

/// free_box with a time step `factor` times its explicit stability limit.
Scene free_box_past_limit(Integrator integ, double factor)
{
    Scene s = free_box(integ, 1.0);
    s.dt = factor * Simulation(s).explicit_dt_limit();
    return s;
}

} // namespace

TEST(SimModel, MassesSumToDensityTimesVolume)
{
    TetMesh m = box_mesh(3, 2.0);
    Material mat;
    mat.density = 250;
    Model model = Model::build(m, {mat}, {0});
    double total = 0;
    for (double v : model.mass)
        total += v;
    EXPECT_NEAR(total, 250 * 8.0, 1e-9 * total);
    EXPECT_EQ(model.springs.edges.rows(), unique_edges(m.tets).rows());
}

TEST(SimModel, StiffnessDirectOrFromTheVolumeAroundTheEdge)
{
    TetMesh m = box_mesh(2);
    Material a;
    a.young = 3e5;
    Model ma = Model::build(m, {a}, {0});
    // Van Gelder: k = young · (volume of the tets around the edge) / L0², the volumes summed here independently.
    std::map<std::pair<Index, Index>, double> around;
    for (Index t = 0; t < m.num_tets(); ++t) {
        const Eigen::Vector3d p0 = m.positions.row(m.tets(t, 0)).transpose();
        const double vol = std::abs((m.positions.row(m.tets(t, 1)).transpose() - p0)
                                        .dot((m.positions.row(m.tets(t, 2)).transpose() - p0)
                                                 .cross(m.positions.row(m.tets(t, 3)).transpose() - p0))) /
                           6.0;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                around[{std::min(m.tets(t, i), m.tets(t, j)), std::max(m.tets(t, i), m.tets(t, j))}] += vol;
    }
    ASSERT_EQ(around.size(), ma.springs.k.size());
    for (size_t e = 0; e < ma.springs.k.size(); ++e) {
        const Index i = ma.springs.edges(static_cast<Index>(e), 0), j = ma.springs.edges(static_cast<Index>(e), 1);
        const double expected =
            3e5 * around.at({std::min(i, j), std::max(i, j)}) / (ma.springs.rest[e] * ma.springs.rest[e]);
        EXPECT_NEAR(ma.springs.k[e], expected, 1e-9 * expected);
    }
    Material b;
    b.stiffness = 42;
    b.damping = 0.5;
    Model mb = Model::build(m, {b}, {0});
    for (size_t e = 0; e < mb.springs.k.size(); ++e) {
        EXPECT_EQ(mb.springs.k[e], 42);
        EXPECT_EQ(mb.springs.c[e], 21);
    }
}

TEST(SimModel, StaticObjectsHaveNoSpringsAndAreFixed)
{
    TetMesh a = box_mesh(2), b = box_mesh(2);
    a.append(b);
    Model m = Model::build(a, {Material{}, Material{}}, {0, 1});
    EXPECT_EQ(m.springs.edges.rows(), unique_edges(b.tets).rows());
    for (Index i = 0; i < a.num_vertices(); ++i)
        EXPECT_EQ(m.fixed[static_cast<size_t>(i)] != 0, i >= b.num_vertices());
}

TEST(SimModel, RestStateHasNoForceAndZeroElasticEnergy)
{
    TetMesh m = box_mesh(2);
    Model model = Model::build(m, {Material{}}, {0});
    Positions f = Positions::Zero(m.num_vertices(), 3), v = Positions::Zero(m.num_vertices(), 3);
    model.add_forces(m.positions, v, f);
    EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-9);
    const Energy e = model.energy(m.positions, v);
    EXPECT_NEAR(e.spring + e.volume, 0.0, 1e-12);
}

TEST(SimModel, ForcesAreMinusEnergyGradient)
{
    TetMesh m = box_mesh(2);
    Material mat;
    mat.volume_stiffness = 3.0;
    Model model = Model::build(m, {mat}, {0});
    const Positions x = perturbed(m.positions, 3, 0.1);
    const Positions v = Positions::Zero(x.rows(), 3);
    Positions f = Positions::Zero(x.rows(), 3);
    model.add_forces(x, v, f);
    auto elastic = [&](const Positions& p) {
        const Energy e = model.energy(p, v);
        return e.spring + e.volume;
    };
    const double h = 1e-6;
    double worst = 0, scale = f.cwiseAbs().maxCoeff();
    for (Index i = 0; i < x.rows(); i += 7)
        for (int c = 0; c < 3; ++c) {
            Positions xp = x, xm = x;
            xp(i, c) += h;
            xm(i, c) -= h;
            const double grad = (elastic(xp) - elastic(xm)) / (2 * h);
            worst = std::max(worst, std::abs(-grad - f(i, c)));
        }
    EXPECT_LT(worst, 1e-5 * scale);
    // Internal forces sum to zero (momentum conserving).
    EXPECT_LT(f.colwise().sum().cwiseAbs().maxCoeff(), 1e-9 * scale);
}

TEST(SimModel, MatrixFreeOperatorEqualsAssembledMatrix)
{
    TetMesh m = box_mesh(2);
    Material mat;
    mat.damping = 0.1;
    Model model = Model::build(m, {mat}, {0});
    model.fixed[0] = 1; // a pinned vertex: its rows and columns are skipped by both
    model.ground.enabled = true;
    model.ground.height = -0.45;
    model.ground.stiffness = 1e3;
    model.ground.damping = 5;
    const Positions x = perturbed(m.positions, 5, 0.08);
    std::vector<Eigen::Triplet<double>> t;
    model.add_matrix_triplets(x, 0.7, 0.3, t);
    const Index N = 3 * x.rows();
    Eigen::SparseMatrix<double> A(N, N);
    A.setFromTriplets(t.begin(), t.end());
    Eigen::VectorXd p = Eigen::VectorXd::Random(N);
    p.head<3>().setZero();
    Eigen::VectorXd out = Eigen::VectorXd::Zero(N);
    model.apply_matrix(x, 0.7, 0.3, p, out);
    EXPECT_LT((A * p - out).norm(), 1e-9 * out.norm());
    Eigen::VectorXd diag = Eigen::VectorXd::Zero(N);
    model.add_matrix_diagonal(x, 0.7, 0.3, diag);
    EXPECT_LT((Eigen::VectorXd(A.diagonal()) - diag).norm(), 1e-9 * diag.norm());
    EXPECT_LT((Eigen::SparseMatrix<double>(A.transpose()) - A).norm(), 1e-9 * A.norm()); // symmetric

    // The linearised (cached) operator used by CG gives the same products and diagonal.
    const Model::Linearised lin = model.linearise(x, 0.7, 0.3);
    Eigen::VectorXd out2 = Eigen::VectorXd::Zero(N), diag2 = Eigen::VectorXd::Zero(N);
    lin.apply(p, out2);
    lin.add_diagonal(diag2);
    EXPECT_LT((out2 - out).norm(), 1e-9 * out.norm());
    EXPECT_LT((diag2 - diag).norm(), 1e-9 * diag.norm());

    // Per-vertex ground coefficients (automatic ground) enter all three the same way.
    model.ground_k.assign(static_cast<size_t>(x.rows()), 0.0);
    model.ground_c.assign(static_cast<size_t>(x.rows()), 0.0);
    for (Index i = 0; i < x.rows(); ++i) {
        model.ground_k[static_cast<size_t>(i)] = 500.0 + 100.0 * static_cast<double>(i % 7);
        model.ground_c[static_cast<size_t>(i)] = 1.0 + static_cast<double>(i % 3);
    }
    t.clear();
    model.add_matrix_triplets(x, 0.7, 0.3, t);
    A.setFromTriplets(t.begin(), t.end());
    out.setZero();
    model.apply_matrix(x, 0.7, 0.3, p, out);
    out2.setZero();
    model.linearise(x, 0.7, 0.3).apply(p, out2);
    EXPECT_LT((A * p - out).norm(), 1e-9 * out.norm());
    EXPECT_LT((out2 - out).norm(), 1e-9 * out.norm());
}

TEST(SimModel, ZeroVolumeRestTetIsRefused)
{
    TetMesh m = box_mesh(2);
    const Index t = 5;
    for (int k = 1; k < 4; ++k)
        m.positions.row(m.tets(t, k)) = m.positions.row(m.tets(t, 0));
    expect_error([&] { Model::build(m, {Material{}}, {0}); }, {"zero"});
}

TEST(SimIntegrators, SymplecticEulerEnergyOscillatesBounded)
{
    Scene s = free_box(Integrator::symplectic_euler, 1.0);
    s.dt = 0.1 * Simulation(s).explicit_dt_limit();
    Simulation sim(s);
    EXPECT_TRUE(sim.warnings().empty());
    const double e0 = sim.energy().total();
    ASSERT_GT(e0, 0);
    double lo = e0, hi = e0;
    for (int i = 0; i < 2000; ++i) {
        sim.step();
        const double e = sim.energy().total();
        lo = std::min(lo, e);
        hi = std::max(hi, e);
    }
    // Symplectic: no drift, a bounded oscillation of a few percent at a tenth of the limit.
    EXPECT_LT(hi - lo, 0.05 * e0) << "lo " << lo << " hi " << hi;
    EXPECT_LT(sim.momentum().norm(), 1e-9);
}

TEST(SimIntegrators, ImplicitEulerEnergyNonIncreasing)
{
    for (LinearSolver solver : {LinearSolver::cg, LinearSolver::ldlt}) {
        Scene s = free_box_past_limit(Integrator::implicit_euler, 20); // far above the explicit limit
        s.solver = solver;
        s.tolerance = 1e-10;
        Simulation sim(s);
        double prev = sim.energy().total();
        const double e0 = prev;
        for (int i = 0; i < 200; ++i) {
            sim.step();
            const double e = sim.energy().total();
            EXPECT_LE(e, prev * (1 + 1e-6) + 1e-12 * e0) << "step " << i << " solver " << to_string(solver);
            prev = e;
        }
        EXPECT_LT(prev, 0.5 * e0); // and it dissipates
    }
}

TEST(SimIntegrators, LocalGlobalEnergyBoundedAtLargeSteps)
{
    Scene s = free_box_past_limit(Integrator::vbd, 20);
    s.iterations = 10;
    Simulation sim(s);
    const double e0 = sim.energy().total();
    for (int i = 0; i < 200; ++i) {
        sim.step();
        EXPECT_LE(sim.energy().total(), 1.05 * e0) << "step " << i;
    }
    EXPECT_TRUE(sim.positions().allFinite());
}

TEST(SimIntegrators, ExplicitAboveLimitWarnsThenStopsWithoutNaN)
{
    Scene s = free_box_past_limit(Integrator::symplectic_euler, 5);
    Simulation sim(s);
    ASSERT_FALSE(sim.warnings().empty());
    EXPECT_NE(sim.warnings()[0].find("stability limit"), std::string::npos) << sim.warnings()[0];
    try {
        for (int i = 0; i < 10000; ++i)
            sim.step();
        FAIL() << "no blow-up detected";
    } catch (const RunFailure& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("step"), std::string::npos) << msg;
        EXPECT_NE(msg.find("stability limit"), std::string::npos) << msg;
    }
    EXPECT_TRUE(sim.positions().allFinite());
    EXPECT_TRUE(sim.velocities().allFinite());
}

TEST(SimIntegrators, SubstepsBringExplicitUnderTheLimit)
{
    Scene s = free_box_past_limit(Integrator::symplectic_euler, 3);
    s.substeps = 6;
    Simulation sim(s);
    EXPECT_TRUE(sim.warnings().empty());
    for (int i = 0; i < 300; ++i)
        sim.step();
    EXPECT_TRUE(sim.positions().allFinite());
}

TEST(SimIntegrators, PinnedVerticesStayPut)
{
    for (Integrator integ : {Integrator::symplectic_euler, Integrator::implicit_euler, Integrator::vbd}) {
        Scene s = free_box(integ, 1e-4, 0.01, 0.0);
        s.gravity = Eigen::Vector3d(0, 0, -9.81);
        PinRegion p;
        p.has_box = true;
        p.box_min = Eigen::Vector3d(-1, -1, 0.4);
        p.box_max = Eigen::Vector3d(1, 1, 1);
        s.pins.push_back(p);
        Simulation sim(s);
        const Positions x0 = sim.positions();
        for (int i = 0; i < 50; ++i)
            sim.step();
        Index pinned = 0;
        for (Index i = 0; i < x0.rows(); ++i)
            if (x0(i, 2) >= 0.4) {
                ++pinned;
                EXPECT_EQ((sim.positions().row(i) - x0.row(i)).norm(), 0.0);
            }
        EXPECT_GT(pinned, 0);
        EXPECT_LT(sim.positions().col(2).minCoeff(), x0.col(2).minCoeff()); // the rest sags
    }
}

TEST(SimModel, EnergyIsTheSameAtAnyThreadCount)
{
    // A box of several blocks of 4,096 tets, shaken, with velocities: the energies the same bits at
    // 1, 2 and 3 threads, and equal to a plain serial sum to rounding.
    TetMesh m = box_mesh(14);
    ASSERT_GT(m.num_tets(), 3 * 4096);
    Material mat;
    mat.young = 1e5;
    Model model = Model::build(m, {mat}, {0});
    const Positions x = perturbed(m.positions, 3, 0.06);
    const Positions v = perturbed(Positions::Zero(m.num_vertices(), 3), 4, 1.0);
    const Energy e1 = model.energy(x, v, 1);
    for (const int threads : {2, 3}) {
        const Energy e = model.energy(x, v, threads);
        EXPECT_EQ(e.kinetic, e1.kinetic) << threads;
        EXPECT_EQ(e.spring, e1.spring) << threads;
        EXPECT_EQ(e.volume, e1.volume) << threads;
        EXPECT_EQ(e.gravity, e1.gravity) << threads;
        EXPECT_EQ(e.ground, e1.ground) << threads;
    }
    double spring = 0;
    for (Index e = 0; e < model.springs.edges.rows(); ++e) {
        const double len = (x.row(model.springs.edges(e, 0)) - x.row(model.springs.edges(e, 1))).norm();
        spring += 0.5 * model.springs.k[static_cast<size_t>(e)] *
                  std::pow(len - model.springs.rest[static_cast<size_t>(e)], 2);
    }
    EXPECT_NEAR(e1.spring, spring, 1e-12 * spring);
    double kinetic = 0;
    for (Index i = 0; i < x.rows(); ++i)
        kinetic += 0.5 * model.mass[static_cast<size_t>(i)] * v.row(i).squaredNorm();
    EXPECT_NEAR(e1.kinetic, kinetic, 1e-12 * kinetic);
}

TEST(SimModel, EnergyPassFindsTheInvertedTetsAndTheVolume)
{
    // A step's checks read the energy, the inverted tets and the volume from one pass over the tets: each must be the
    // bits of a pass of its own (signed_volume, its energy and the volumes summed in blocks of 4,096 tets; the tets of
    // signed volume ≤ 0 in order), at one thread and at two, on a box shaken until some of its tets turn inside out.
    TetMesh m = box_mesh(14);
    ASSERT_GT(m.num_tets(), 3 * 4096);
    Material mat;
    mat.young = 1e5;
    const Model model = Model::build(m, {mat}, {0});
    const Positions x = perturbed(m.positions, 5, 0.05);
    const Positions v = perturbed(Positions::Zero(m.num_vertices(), 3), 6, 1.0);
    const Tets& tets = model.volumes.tets;
    double volume_energy = 0, six_volume = 0;
    std::vector<std::int32_t> inverted;
    for (Index b = 0; b < tets.rows(); b += 4096) {
        double part = 0, six_part = 0;
        for (Index t = b; t < std::min<Index>(tets.rows(), b + 4096); ++t) {
            const double vol = signed_volume(x, {tets(t, 0), tets(t, 1), tets(t, 2), tets(t, 3)});
            const double v0 = model.volumes.rest[static_cast<size_t>(t)];
            part += 0.5 * model.volumes.k[static_cast<size_t>(t)] * (vol - v0) * (vol - v0) / v0;
            six_part += 6 * vol;
            if (!(vol > 0)) inverted.push_back(static_cast<std::int32_t>(t));
        }
        volume_energy += part;
        six_volume += six_part;
    }
    ASSERT_GT(inverted.size(), 10u);
    for (const int threads : {1, 2}) {
        Model::TetScan scan;
        scan.inverted = {1, 2, 3}; // replaced, not appended to
        const Energy with = model.energy(x, v, threads, &scan);
        const Energy without = model.energy(x, v, threads);
        EXPECT_EQ(scan.inverted, inverted) << threads;
        EXPECT_NEAR(scan.volume, six_volume / 6, 1e-14 * std::abs(six_volume)) << threads;
        EXPECT_EQ(with.volume, volume_energy) << threads;
        EXPECT_EQ(without.volume, volume_energy) << threads;
        EXPECT_EQ(with.spring, without.spring) << threads;
        EXPECT_EQ(with.kinetic, without.kinetic) << threads;
    }
}
