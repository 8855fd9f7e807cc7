// The vbd coarse space's lattice (src/sim/coarse_space.hpp): how many nodes an object gets. Its factorisation is
// redone at most substeps and grows faster than the square of the nodes, so where a substep converges in a few
// sweeps (ω h of a few tens: a 15 cm body at 1/240) the lattice stays small, and only where ω h makes a substep
// need many sweeps (a stiff or small body at a long step) does it get the finer one.
#include "../src/sim/coarse_space.hpp"

#include "tethash/meshing/generate.hpp"
#include "tethash/sim/model.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace tethash;
using namespace tethash::sim;

namespace {

/// A body's mesh and model.
struct Body {
    TetMesh mesh;
    Model model;
};

/// A generated box of `resolution` cells along its longest side, young 1e5, density 1000 and `damping`, as one object.
Body box_body(int resolution, const Eigen::Vector3d& size, double damping = Material{}.damping)
{
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = resolution;
    g.size = size;
    Body out;
    out.mesh = meshing::generate(g);
    Material m;
    m.young = 1e5;
    m.density = 1000;
    m.damping = damping;
    out.model = Model::build(out.mesh, {m}, {0});
    return out;
}

/// Nodes of the lattice over a box of young `young` (1 m, 2,000 vertices and more, so that a quarter of its
/// vertices does not bind) built for a substep h = omega_h / ω.
std::int32_t lattice_nodes(double omega_h)
{
    const auto [mesh, model] = box_body(12, Eigen::Vector3d::Constant(1.0));
    EXPECT_GE(mesh.num_vertices(), 1600);
    const double omega = std::sqrt(model.object_frequency_sq[0]);
    detail::CoarseSpace coarse;
    coarse.build(model, mesh.positions, {0.0}, omega_h / omega);
    return coarse.nodes();
}

} // namespace

TEST(SimCoarseSpace, LatticeStaysSmallWhereASubstepNeedsFewSweeps)
{
    // ω h 12 asks for cells of a fifteenth of the extent (thousands of nodes): the cap is 200 there, 400 beyond
    // ω h 50 (a body of young 1e9 at 15 cm and 1/60 took three times the sweeps with 200).
    const std::int32_t moderate = lattice_nodes(12.0);
    const std::int32_t stiff = lattice_nodes(100.0);
    EXPECT_GT(moderate, 100);
    EXPECT_LE(moderate, 200);
    EXPECT_GT(stiff, 200);
    EXPECT_LE(stiff, 400);
}

namespace {

/// Two boxes (1 m and a turned 0.4 m one) as two objects, a few vertices of the first pinned.
Body two_bodies()
{
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = 5;
    g.size = Eigen::Vector3d(1.0, 0.6, 0.5);
    const TetMesh a = meshing::generate(g);
    g.resolution = 4;
    g.size = Eigen::Vector3d::Constant(0.4);
    TetMesh b = meshing::generate(g);
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    for (Index i = 0; i < b.num_vertices(); ++i)
        b.positions.row(i) = (turn * b.positions.row(i).transpose() + Eigen::Vector3d(0.2, 0.1, 0.9)).transpose();
    Body out;
    TetMesh& m = out.mesh;
    m.positions.resize(a.num_vertices() + b.num_vertices(), 3);
    m.positions << a.positions, b.positions;
    m.tets.resize(a.num_tets() + b.num_tets(), 4);
    m.tets << a.tets, (b.tets.array() + a.num_vertices()).matrix();
    m.vertex_object.assign(static_cast<size_t>(a.num_vertices()), 0);
    m.vertex_object.resize(static_cast<size_t>(m.num_vertices()), 1);
    m.tet_object.assign(static_cast<size_t>(a.num_tets()), 0);
    m.tet_object.resize(static_cast<size_t>(m.num_tets()), 1);
    Material soft;
    soft.young = 1e5;
    soft.density = 1000;
    soft.damping = 0.01;
    Material stiff = soft;
    stiff.young = 1e6;
    out.model = Model::build(m, {soft, stiff}, {0, 0});
    // Pin the first box's vertices at x < −0.4 (their rows and columns of the fine matrix drop out).
    for (Index i = 0; i < a.num_vertices(); ++i)
        if (m.positions(i, 0) < -0.4) out.model.fixed[static_cast<size_t>(i)] = 1;
    return out;
}

/// The fine matrix the lattice is the Galerkin product of: K + C / h at the start (no ground), the volume terms'
/// relative damping, the masses / h² of the vertices in a lattice (pinned ones 10⁴ times).
Eigen::SparseMatrix<double> fine_matrix(const Model& model, const Positions& x, const std::vector<double>& damping,
                                        const std::vector<char>& in_lattice, double h)
{
    Model elastic = model;
    elastic.ground.enabled = false;
    std::vector<Eigen::Triplet<double>> trip;
    elastic.add_matrix_triplets(x, 1.0, 1.0 / h, trip);
    // The volume terms' damping: (damping / h) k / 6V0 g gᵀ on the free vertices.
    Model damped = elastic;
    damped.springs.k.assign(damped.springs.k.size(), 0.0);
    damped.springs.c.assign(damped.springs.c.size(), 0.0);
    for (Index t = 0; t < damped.volumes.tets.rows(); ++t) {
        const size_t o = static_cast<size_t>(model.vertex_object[static_cast<size_t>(damped.volumes.tets(t, 0))]);
        damped.volumes.k[static_cast<size_t>(t)] *= damping[o] / h;
    }
    damped.add_matrix_triplets(x, 1.0, 0.0, trip);
    for (Index i = 0; i < model.num_vertices(); ++i) {
        const size_t u = static_cast<size_t>(i);
        if (!in_lattice[u]) continue;
        const double m = model.mass[u] / (h * h) * (model.fixed[u] ? 1e4 : 1.0);
        for (Index r = 0; r < 3; ++r)
            trip.emplace_back(3 * i + r, 3 * i + r, m);
    }
    Eigen::SparseMatrix<double> a(3 * model.num_vertices(), 3 * model.num_vertices());
    a.setFromTriplets(trip.begin(), trip.end());
    return a;
}

} // namespace

TEST(SimCoarseSpace, AssembledMatrixIsTheGalerkinProductOfTheFineMatrix)
{
    // The lattice's matrix is assembled element by element on the nodes: it must be Pᵀ A P of the fine matrix (plus
    // the small floor on the diagonal), across two objects, pinned vertices and the springs' and volumes' damping; and
    // after prepare() with ground or contact blocks on some vertices, Pᵀ (A + E) P.
    const Body bodies = two_bodies();
    const Model& model = bodies.model;
    const std::vector<double> damping = {0.01, 0.01};
    const double h = 1.0 / 240;
    detail::CoarseSpace coarse;
    coarse.build(model, bodies.mesh.positions, damping, h);
    ASSERT_GT(coarse.nodes(), 16);
    const Eigen::SparseMatrix<double> p = coarse.prolongation();
    std::vector<char> in_lattice(static_cast<size_t>(model.num_vertices()), 0);
    double mass_sum = 0;
    for (Index i = 0; i < model.num_vertices(); ++i)
        if (p.row(3 * i).sum() > 0) {
            in_lattice[static_cast<size_t>(i)] = 1;
            mass_sum += model.mass[static_cast<size_t>(i)];
        }
    const Eigen::SparseMatrix<double> a = fine_matrix(model, bodies.mesh.positions, damping, in_lattice, h);
    Eigen::MatrixXd expected = Eigen::MatrixXd(Eigen::SparseMatrix<double>(p.transpose() * (a * p)));
    const double floor = 1e-6 * mass_sum / (h * h) / coarse.nodes();
    expected.diagonal().array() += floor;
    const Eigen::MatrixXd got = coarse.start_matrix(h);
    const double scale = expected.cwiseAbs().maxCoeff();
    EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-12 * scale);
    EXPECT_LT((got - got.transpose()).cwiseAbs().maxCoeff(), 1e-12 * scale);

    // Ground-like blocks on the lowest vertices and a contact-like block on a vertex of each body.
    const size_t un = static_cast<size_t>(model.num_vertices());
    std::vector<double> extra(6 * un, 0.0);
    std::vector<std::int32_t> with_extra;
    Eigen::SparseMatrix<double> e(3 * model.num_vertices(), 3 * model.num_vertices());
    std::vector<Eigen::Triplet<double>> etrip;
    for (size_t i = 0; i < un; ++i) {
        const bool low = bodies.mesh.positions(static_cast<Index>(i), 2) < -0.2;
        if (!low && i != un - 1 && i != un / 3) continue;
        const double k = 1e3 * (1.0 + static_cast<double>(i % 7));
        const double blk[6] = {0.3 * k, 0.2 * k, k, 0.05 * k, -0.02 * k, 0.1 * k}; // xx yy zz xy xz yz
        for (size_t q = 0; q < 6; ++q)
            extra[6 * i + q] = blk[q];
        with_extra.push_back(static_cast<std::int32_t>(i));
        const Index b = 3 * static_cast<Index>(i);
        const Eigen::Matrix3d m{{blk[0], blk[3], blk[4]}, {blk[3], blk[1], blk[5]}, {blk[4], blk[5], blk[2]}};
        for (Index r = 0; r < 3; ++r)
            for (Index c = 0; c < 3; ++c)
                etrip.emplace_back(b + r, b + c, m(r, c));
    }
    e.setFromTriplets(etrip.begin(), etrip.end());
    std::vector<double> x4(4 * un, 0.0);
    for (size_t i = 0; i < un; ++i)
        for (size_t r = 0; r < 3; ++r)
            x4[4 * i + r] = bodies.mesh.positions(static_cast<Index>(i), static_cast<Index>(r));
    ASSERT_TRUE(coarse.prepare(h, x4.data(), extra, with_extra));
    expected += Eigen::MatrixXd(Eigen::SparseMatrix<double>(p.transpose() * (e * p)));
    const Eigen::MatrixXd prepared = Eigen::MatrixXd(coarse.matrix());
    EXPECT_LT((prepared - expected).cwiseAbs().maxCoeff(), 1e-10 * scale);
}

TEST(SimCoarseSpace, RefreshAndCorrectionAreBitIdenticalAtOneAndTwoThreads)
{
    // The matrix's refresh splits its block rows over the threads, the restriction its nodes and the prolongation its
    // vertices: every sum is taken in the same order at any count (a box large enough for the parallel paths).
    const auto [mesh, model] = box_body(18, Eigen::Vector3d(1.0, 0.7, 0.5), 0.01);
    const size_t un = static_cast<size_t>(model.num_vertices());
    ASSERT_GT(un, 4096u);
    const double h = 12.0 / std::sqrt(model.object_frequency_sq[0]); // ω h 12: about 200 nodes
    // A turned and bent state (bent enough for the cells near the ends to be turned apart from the object, in
    // parallel), ground-like blocks on the lowest vertices, a residual of every sign.
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
    std::vector<double> x4(4 * un, 0.0), extra(6 * un, 0.0), r(3 * un);
    std::vector<std::int32_t> with_extra;
    for (size_t i = 0; i < un; ++i) {
        const Eigen::Vector3d p = mesh.positions.row(static_cast<Index>(i)).transpose();
        const Eigen::Vector3d q = turn * p + Eigen::Vector3d(0, 0, 0.8 * p.x() * p.x());
        for (size_t c = 0; c < 3; ++c) {
            x4[4 * i + c] = q[static_cast<Index>(c)];
            r[3 * i + c] = std::sin(0.37 * static_cast<double>(3 * i + c));
        }
        if (p.z() < -0.2) {
            for (size_t c = 0; c < 6; ++c)
                extra[6 * i + c] = (c < 3 ? 1e3 : 1e2) * (1.0 + 0.1 * static_cast<double>(i % 5));
            with_extra.push_back(static_cast<std::int32_t>(i));
        }
    }
    std::vector<double> dx[2];
    std::vector<double> values[2];
    for (int threads = 1; threads <= 2; ++threads) {
        detail::CoarseSpace coarse;
        coarse.build(model, mesh.positions, {0.01}, h);
        coarse.set_threads(threads);
        ASSERT_GT(coarse.nodes(), 100);
        ASSERT_GT(coarse.matrix().nonZeros(), 9 * 2048);
        ASSERT_TRUE(coarse.prepare(h, x4.data(), extra, with_extra));
        EXPECT_GT(coarse.cells_turned_apart(), 16u);
        coarse.correct(r, dx[threads - 1]);
        values[threads - 1].assign(coarse.matrix().valuePtr(), coarse.matrix().valuePtr() + coarse.matrix().nonZeros());
    }
    EXPECT_EQ(values[0], values[1]);
    EXPECT_EQ(dx[0], dx[1]);
    // The correction is not trivially zero.
    double norm = 0;
    for (const double d : dx[0])
        norm += d * d;
    EXPECT_GT(norm, 0.0);
}

TEST(SimCoarseSpace, PartTurnedAgainstTheBodyKeepsItsStiffnessAlongItsSprings)
{
    // A bar whose far half turned by 1.2 rad about z against its near half (a leg turned against the body): the
    // lattice's matrix at that state is to be close to the Galerkin product of the fine matrix there, Pᵀ A(x) P. With
    // the object's one rotation (the polar factor of the whole, about half the turn) both halves' stiffness points
    // 0.6 rad off their springs; each lattice cell turned by its own vertices' rotation puts it back along them
    // (except in the cells at the joint, which the turn shears).
    const auto [mesh, model] = box_body(10, Eigen::Vector3d(2.0, 0.4, 0.4));
    const double h = 40.0 / std::sqrt(model.object_frequency_sq[0]); // ω h 40: cells of about two mean edges
    detail::CoarseSpace coarse;
    coarse.build(model, mesh.positions, {0.0}, h);
    ASSERT_GT(coarse.nodes(), 60);
    const size_t un = static_cast<size_t>(model.num_vertices());
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Positions x = mesh.positions;
    std::vector<double> x4(4 * un, 0.0);
    for (size_t i = 0; i < un; ++i) {
        const Eigen::Vector3d p = mesh.positions.row(static_cast<Index>(i)).transpose();
        const Eigen::Vector3d q = p.x() > 0 ? Eigen::Vector3d(turn * p) : p;
        x.row(static_cast<Index>(i)) = q.transpose();
        for (size_t c = 0; c < 3; ++c)
            x4[4 * i + c] = q[static_cast<Index>(c)];
    }
    ASSERT_TRUE(coarse.prepare(h, x4.data(), {}, {}));
    const Eigen::SparseMatrix<double> p = coarse.prolongation();
    const std::vector<char> in_lattice(un, 1);
    const Eigen::MatrixXd exact =
        Eigen::MatrixXd(Eigen::SparseMatrix<double>(p.transpose() * (fine_matrix(model, x, {0.0}, in_lattice, h) * p)));
    // The start matrix turned by the object's one rotation (what the lattice had before its cells' own rotations).
    Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
    Eigen::Vector3d c = Eigen::Vector3d::Zero(), c0 = Eigen::Vector3d::Zero();
    double mass = 0;
    for (size_t i = 0; i < un; ++i) {
        mass += model.mass[i];
        c += model.mass[i] * x.row(static_cast<Index>(i)).transpose();
        c0 += model.mass[i] * mesh.positions.row(static_cast<Index>(i)).transpose();
    }
    c /= mass;
    c0 /= mass;
    for (size_t i = 0; i < un; ++i)
        s += model.mass[i] * (x.row(static_cast<Index>(i)).transpose() - c) *
             (mesh.positions.row(static_cast<Index>(i)).transpose() - c0).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(s, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d whole = svd.matrixU() * svd.matrixV().transpose();
    ASSERT_GT(Eigen::AngleAxisd(whole).angle(), 0.4);
    const Eigen::MatrixXd start = coarse.start_matrix(h);
    Eigen::MatrixXd one_rotation = start;
    for (Index a = 0; a < coarse.nodes(); ++a)
        for (Index b = 0; b < coarse.nodes(); ++b)
            one_rotation.block<3, 3>(3 * a, 3 * b) = whole * start.block<3, 3>(3 * a, 3 * b) * whole.transpose();
    const Eigen::MatrixXd got = Eigen::MatrixXd(coarse.matrix());
    const double off_by_cells = (got - exact).norm(), off_by_object = (one_rotation - exact).norm();
    EXPECT_GT(coarse.cells_turned_apart(), 0u);
    EXPECT_LT(off_by_cells, 0.5 * off_by_object) << "cells " << off_by_cells << ", object " << off_by_object;
    EXPECT_LT((got - got.transpose()).cwiseAbs().maxCoeff(), 1e-9 * got.cwiseAbs().maxCoeff());
}
