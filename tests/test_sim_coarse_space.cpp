// The vbd coarse space's lattice (src/sim/coarse_space.hpp): how many nodes an object gets. Its factorisation is
// redone at most substeps and grows faster than the square of the nodes, so where a substep converges in a few
// sweeps (ω h of a few tens: a 15 cm body at 1/240) the lattice stays small, and only where ω h makes a substep
// need many sweeps (a stiff or small body at a long step) does it get the finer one.
#include "../src/sim/coarse_space.hpp"

#include "tethash/meshing/generate.hpp"
#include "tethash/sim/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace tethash;
using namespace tethash::sim;

namespace {

/// Nodes of the lattice over a box of young `young` (1 m, 2,000 vertices and more, so that a quarter of its
/// vertices does not bind) built for a substep h = omega_h / ω.
std::int32_t lattice_nodes(double omega_h)
{
    meshing::GenerateParams g;
    g.shape = "box";
    g.resolution = 12;
    g.size = Eigen::Vector3d::Constant(1.0);
    const TetMesh mesh = meshing::generate(g);
    EXPECT_GE(mesh.num_vertices(), 1600);
    Material m;
    m.young = 1e5;
    m.density = 1000;
    const Model model = Model::build(mesh, {m}, {0});
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
